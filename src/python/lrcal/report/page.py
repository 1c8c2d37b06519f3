"""lrcal.report's page of a study run: RUN_DIR/report/report.html, a single self-contained page
(figures embedded as PNG, also written as PNG and SVG in RUN_DIR/report/figures/), the tables,
the study settings, the manifest and the failures by reason. `lrcal report RUN_DIR` first
prepares the tables, the summary's blocks and the one-realisation data from the run's records,
then runs `python3 -m lrcal.report RUN_DIR`.
"""
import base64
import html
import json
import os
import time

from . import figures as _figures


def _inline(text):
    """Escaped text with `code` spans as <code>."""
    parts = html.escape(text).split("`")
    return "".join(f"<code>{p}</code>" if k % 2 else p for k, p in enumerate(parts))


def table_html(header, rows):
    """A table of strings (lrcal formats every number; the header says its unit)."""
    out = ["<table>", "<tr>" + "".join(f"<th>{html.escape(h)}</th>" for h in header) + "</tr>"]
    out.extend("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in row) + "</tr>"
               for row in rows)
    out.append("</table>")
    return "\n".join(out)


def document_html(blocks):
    """The summary's blocks (report/document.json, what summary.md says) as HTML; the page has
    its own title, so the document's is left out and its headings become h3."""
    out = []
    for b in blocks:
        kind = b.get("kind")
        if kind == "heading":
            out.append(f"<h3>{_inline(b['text'])}</h3>")
        elif kind == "paragraph":
            out.append(f"<p>{_inline(b['text'])}</p>")
        elif kind == "note":
            out.append(f"<p class='partial'><b>{_inline(b['text'])}</b></p>")
        elif kind == "table":
            if b.get("title"):
                out.append(f"<p class='caption'>{_inline(b['title'])}</p>")
            out.append(table_html(b["header"], b["rows"]))
        elif kind != "title":
            raise _figures.RunDataError(f"document.json: unknown block kind {kind!r}")
    return "\n".join(out)


STYLE = """
body { font-family: sans-serif; margin: 2em auto; max-width: 1200px; color: #222; }
h1 { margin-bottom: 0.2em; } h2 { border-bottom: 1px solid #ccc; margin-top: 2em; }
table { border-collapse: collapse; margin: 0.6em 0; font-size: 0.85em; }
td, th { border: 1px solid #ccc; padding: 2px 6px; text-align: right; }
th { background: #f2f2f2; } td:first-child, th:first-child { text-align: left; }
.partial { background: #fff3cd; border: 1px solid #e0c060; padding: 0.6em 1em; }
figure { margin: 1.2em 0; } figure img { max-width: 100%; border: 1px solid #eee; }
figcaption { font-size: 0.9em; color: #444; } pre { background: #f7f7f7; padding: 0.6em;
overflow-x: auto; font-size: 0.8em; } .caption { font-weight: bold; }
"""

# Checks, once the page has loaded, that every figure decoded; the result goes into the title so
# a headless browser test can read it.
CHECK = """
window.addEventListener('load', function () {
  var imgs = document.querySelectorAll('img.figure');
  var ok = 0;
  imgs.forEach(function (img) { if (img.complete && img.naturalWidth > 0) ok++; });
  document.title = 'lrcal report: ' + ok + '/' + imgs.length + ' figures';
  document.body.setAttribute('data-figures-ok', String(ok));
});
"""


def figure_html(png, caption, base_dir):
    """A figure embedded as PNG (the page stays self-contained), with its caption and a link to
    its SVG twin, relative to base_dir (where the page is)."""
    with open(png, "rb") as f:
        data = base64.b64encode(f.read()).decode("ascii")
    svg = os.path.relpath(png[:-4] + ".svg", base_dir)
    return (f"<figure><img class='figure' alt='{html.escape(caption)}' "
            f"src='data:image/png;base64,{data}'><figcaption>{html.escape(caption)} "
            f"(<a href='{html.escape(svg)}'>SVG</a>)</figcaption></figure>")


# A study's list of cells (ids and labels) is shown whole up to this many cells; a larger one is
# in tables/cells.csv, and the page stays small.
MAX_CELLS_LISTED = 24


def _settings(study):
    """The study settings as the page shows them: a long list of cells replaced by a note."""
    cells = study.get("cells")
    if not isinstance(cells, list) or len(cells) <= MAX_CELLS_LISTED:
        return study
    shown = dict(study)
    shown["cells"] = (f"{len(cells)} cells: their ids, labels and varied settings are in "
                      "tables/cells.csv")
    return shown


def build(run_dir):
    t0 = time.time()
    run = _figures.Run(run_dir)
    fig_dir = os.path.join(run.report_dir, "figures")
    figures = _figures.all_figures(run, fig_dir)
    study = run.manifest.get("study", {})
    status = run.status
    parts = ["<!DOCTYPE html><html><head><meta charset='utf-8'>",
             f"<title>lrcal report: {html.escape(study.get('name', '?'))}</title>",
             f"<style>{STYLE}</style></head><body>",
             f"<h1>Study <code>{html.escape(study.get('name', '?'))}</code></h1>",
             f"<p>{html.escape(study.get('description', ''))}</p>",
             f"<p>{status['done']} of {status['expected']} trials; seed {study.get('seed')}; "
             f"{len(run.cells)} cells. Lengths in mm, angles in mrad.</p>"]
    if not status.get("complete"):
        parts.append("<p class='partial'><b>Partial run:</b> this report shows the "
                     f"{status['done']} trials recorded so far of {status['expected']} (the run is "
                     "still going, or was interrupted: run the same <code>lrcal run</code> command "
                     "again to finish it).</p>")
    if status.get("note"):
        parts.append(f"<p class='partial'>{html.escape(status['note'])}</p>")
    parts.append("<h2>Figures</h2>")
    parts.extend(figure_html(png, caption, run.report_dir) for png, caption in figures)
    parts.append("<h2>Tables</h2>")
    parts.append(document_html(run.document["blocks"]))
    parts.append("<h2>Study settings</h2><pre>" + html.escape(json.dumps(_settings(study),
                                                                        indent=2)) + "</pre>")
    manifest = dict(run.manifest)
    if "study" in manifest:
        manifest["study"] = "(the study settings above)"
    parts.append("<h2>Manifest</h2><details><summary>versions, commit, sessions</summary><pre>" +
                 html.escape(json.dumps(manifest, indent=2)) + "</pre></details>")
    parts.append(f"<script>{CHECK}</script></body></html>")
    path = os.path.join(run.report_dir, "report.html")
    write_atomically(path, "\n".join(parts))
    write_atomically(os.path.join(run.report_dir, "figures.json"),
                     json.dumps({"figures": [os.path.basename(p) for p, _ in figures],
                                 "captions": [c for _, c in figures],
                                 "seconds": round(time.time() - t0, 2)}, indent=2))
    return path, figures


def write_atomically(path, text):
    """Writes text to path whole or not at all: a temporary file, flushed, synced, renamed."""
    tmp = path + ".tmp"
    try:
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except OSError:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise
