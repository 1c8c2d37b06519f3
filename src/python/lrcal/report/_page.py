#!/usr/bin/env python3
"""Writes RUN_DIR/report/report.html: a single self-contained page (figures embedded as PNG,
also written as PNG and SVG in RUN_DIR/report/figures/), the tables, the study settings, the
manifest and the failures by reason. Run by `lrcal report RUN_DIR`, which first prepares the
tables and the one-realisation data from the run's records.

    /usr/bin/python3 analysis/report.py RUN_DIR

Exit code 2, with a message naming the file, for a missing or malformed run directory.
"""
import base64
import html
import json
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import lrcal_analysis as la  # noqa: E402


def markdown_to_html(text):
    """The subset of Markdown that lrcal's summary.md uses: headings, bold lines, paragraphs and
    pipe tables."""
    out, table, paragraph = [], [], []

    def flush_table():
        if not table:
            return
        rows = [r.strip().strip("|").split("|") for r in table if not set(r.strip()) <= set("|-: ")]
        out.append("<table>")
        for i, row in enumerate(rows):
            tag = "th" if i == 0 else "td"
            out.append("<tr>" + "".join(f"<{tag}>{html.escape(c.strip())}</{tag}>" for c in row) + "</tr>")
        out.append("</table>")
        table.clear()

    def flush_paragraph():
        if paragraph:
            out.append("<p>" + html.escape(" ".join(paragraph)).replace("`", "") + "</p>")
            paragraph.clear()

    for line in text.splitlines():
        if line.startswith("|"):
            flush_paragraph()
            table.append(line)
            continue
        flush_table()
        if not line.strip():
            flush_paragraph()
        elif line.startswith("## "):
            flush_paragraph()
            out.append(f"<h3>{html.escape(line[3:])}</h3>")
        elif line.startswith("# "):
            flush_paragraph()  # the page has its own title
        elif line.startswith("**") and line.endswith("**"):
            flush_paragraph()
            out.append(f"<p class='caption'>{html.escape(line.strip('*'))}</p>")
        else:
            paragraph.append(line)
    flush_table()
    flush_paragraph()
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


def build(run_dir):
    t0 = time.time()
    run = la.Run(run_dir)
    fig_dir = os.path.join(run.report_dir, "figures")
    figures = la.all_figures(run, fig_dir)
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
    parts.append(markdown_to_html(run.summary_md))
    parts.append("<h2>Study settings</h2><pre>" + html.escape(json.dumps(study, indent=2)) + "</pre>")
    parts.append("<h2>Manifest</h2><details><summary>versions, commit, sessions</summary><pre>" +
                 html.escape(json.dumps(run.manifest, indent=2)) + "</pre></details>")
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


def main(argv):
    if len(argv) != 2:
        print("usage: report.py RUN_DIR", file=sys.stderr)
        return 2
    try:
        path, figures = build(argv[1])
    except la.RunDataError as e:
        print(f"report.py: error: {e}", file=sys.stderr)
        return 2
    except OSError as e:  # a full disk, a folder that cannot be written
        print(f"report.py: could not write the report: {e}", file=sys.stderr)
        return 5
    print(f"report.py: {len(figures)} figures, {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
