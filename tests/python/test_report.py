"""lrcal.report, the report pages in Python: the module the program runs (python3 -m lrcal.report),
the page's tables from the summary's blocks (report/document.json, not summary.md parsed back),
the study figures read through lrcal.load_run's reader, and the pure-Python part working where
the compiled module is not installed."""
import json
import os
import shutil
import subprocess
import sys
from html import escape

import pytest

import lrcal
from lrcal.report import figures, page

from test_commands import small_study


@pytest.fixture(scope="module")
def reported_run(tmp_path_factory):
    """A small study run, reported by the program (`lrcal report` keeps report/document.json)."""
    tmp = tmp_path_factory.mktemp("report")
    run = str(tmp / "run")
    lrcal.run_study(small_study(tmp), run, threads=2)
    program = os.environ.get("LRCAL_CLI") or shutil.which("lrcal")
    done = subprocess.run([program, "report", run], capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr
    return run


def _package_parent():
    return os.path.dirname(os.path.dirname(os.path.abspath(lrcal.__file__)))


def test_the_page_shows_every_block_of_the_summary(reported_run):
    blocks = json.load(open(os.path.join(reported_run, "report", "document.json")))["blocks"]
    with open(os.path.join(reported_run, "tables", "summary.md"), encoding="utf-8") as f:
        summary = f.read()
    kinds = [b["kind"] for b in blocks]
    assert kinds[0] == "title" and "table" in kinds and "heading" in kinds
    with open(os.path.join(reported_run, "report", "report.html"), encoding="utf-8") as f:
        html = f.read()
    for b in blocks:
        if b["kind"] == "heading":
            assert f"## {b['text']}\n" in summary
            assert f"<h3>{escape(b['text'])}</h3>" in html
        if b["kind"] == "table":
            # Every row has one cell per column, and summary.md has the same row.
            assert all(len(r) == len(b["header"]) for r in b["rows"])
            for r in b["rows"]:
                assert "| " + " | ".join(r) + " |" in summary
    assert page.document_html([{"kind": "paragraph", "text": "a `b` <c>"}]) == \
        "<p>a <code>b</code> &lt;c&gt;</p>"
    with pytest.raises(figures.RunDataError, match="unknown block kind 'chart'"):
        page.document_html([{"kind": "chart"}])


def test_figures_read_the_trials_through_load_runs_reader(reported_run, tmp_path):
    # The page's reader takes the run's own store when given it as the snapshot: the same
    # trials as lrcal.load_run, ok ones only.
    report_copy = tmp_path / "run"
    shutil.copytree(reported_run, report_copy)
    shutil.copy(os.path.join(reported_run, "trials.sqlite"),
                report_copy / "report" / "trials.snapshot.sqlite")
    metrics = figures.Run(str(report_copy)).trial_metrics()
    stored = lrcal.load_run(reported_run).trials
    ok = stored[stored["status"] == "ok"]
    assert len(metrics) == len(ok) == 12
    assert sorted(metrics["val_rms_pos_x_mm"]) == sorted(ok["val_rms_pos_x_mm"])


def test_the_module_runs_as_the_program_runs_it(reported_run, tmp_path):
    env = dict(os.environ, PYTHONPATH=_package_parent())
    done = subprocess.run([sys.executable, "-m", "lrcal.report", reported_run], env=env,
                          capture_output=True, text=True, check=False)
    # The program removed its snapshot once the page was drawn: the module says what to run.
    assert done.returncode == 2
    assert "trials.snapshot.sqlite: missing (run `lrcal report RUN_DIR`" in done.stderr
    done = subprocess.run([sys.executable, "-m", "lrcal.report"], env=env, capture_output=True,
                          text=True, check=False)
    assert done.returncode == 2 and "usage: python3 -m lrcal.report RUN_DIR" in done.stderr
    done = subprocess.run([sys.executable, "-m", "lrcal.report", "--calibration",
                           str(tmp_path)], env=env, capture_output=True, text=True, check=False)
    assert done.returncode == 2 and "calibration.json: expected the JSON" in done.stderr
    assert callable(lrcal.report)  # the function, not the package of the same name
    # The drawing modules are imported when asked for: `import lrcal` needs no matplotlib.
    done = subprocess.run([sys.executable, "-c",
                           "import lrcal, sys; print('matplotlib' in sys.modules)"],
                          env=env, capture_output=True, text=True, check=False)
    assert done.stdout.split() == ["False"], done.stderr


def test_without_the_compiled_module_the_python_part_still_works(reported_run, tmp_path):
    # A copy of the package without _lrcal*.so, as a build without pybind11 installs it.
    copy = tmp_path / "lrcal"
    shutil.copytree(os.path.dirname(lrcal.__file__), copy,
                    ignore=shutil.ignore_patterns("_lrcal*", "__pycache__"))
    script = (
        "import lrcal, sys\n"
        f"run = lrcal.load_run({reported_run!r})\n"
        "print(len(run.trials))\n"
        "try:\n"
        "    lrcal.identify\n"
        "except ImportError as e:\n"
        "    print('ImportError:', e)\n"
        "try:\n"
        "    lrcal.load_run('/nonexistent')\n"
        "except lrcal.InputError as e:\n"
        "    print('InputError:', e, isinstance(e, ValueError))\n")
    done = subprocess.run([sys.executable, "-c", script], env=dict(os.environ,
                                                                   PYTHONPATH=str(tmp_path)),
                          capture_output=True, text=True, check=False, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0] == "12"
    assert lines[1].startswith("ImportError: lrcal.identify needs lrcal's compiled module")
    assert "pybind11-dev" in lines[1]
    assert lines[2].startswith("InputError: /nonexistent: not a run directory") and \
        lines[2].endswith("True")


def test_calibration_parameter_names_stay_clear_of_the_next_panel(monkeypatch, tmp_path):
    """Issue 31: with ranger terms the angle panel's rotated names ran into the panel below and
    the last length name was cut at the figure's edge."""
    from lrcal.report import calibration
    captured = []
    monkeypatch.setattr(calibration, "save", lambda fig, *args: captured.append(fig))
    names = ["a1", "a3", "d3", "a4", "d4", "a5", "d5", "a6", "ranger_offset",
             "theta1", "alpha1", "theta2", "alpha2", "beta2", "theta3", "alpha3", "theta4",
             "alpha4", "theta5", "alpha5", "theta6", "alpha6", "beta6", "ranger_scale"]
    params = [{"name": n, "delta": 1e-4 * (k - 10), "std": 1e-5} for k, n in enumerate(names)]
    calibration.parameter_figure({"parameters": params}, str(tmp_path), [])
    fig = captured[0]
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    width = fig.bbox.width
    for upper, lower in zip(fig.axes, fig.axes[1:]):
        labels = [t.get_window_extent(renderer) for t in upper.get_xticklabels() if t.get_text()]
        assert min(b.y0 for b in labels) > lower.get_window_extent(renderer).y1
    for ax in fig.axes:
        for t in ax.get_xticklabels():
            box = t.get_window_extent(renderer)
            assert box.x0 >= 0 and box.x1 <= width, t.get_text()


def test_cell_tick_labels_are_short_values_with_their_keys_on_the_axis():
    """Issue 31: sweep cells' labels ("noise.sigma_mm=0.30000000000000004, selection.count=30")
    overlapped under the box plots; the ticks keep the values, to 4 digits, the axis the keys."""
    cells = [{"label": f"noise.sigma_mm={s}, selection.count={k}"}
             for s in (0.05, 0.30000000000000004) for k in (30, 60)]
    ticks, xlabel = figures._cell_ticks(cells)
    assert ticks == ["0.05, 30", "0.05, 60", "0.3, 30", "0.3, 60"]
    assert xlabel == "noise.sigma_mm, selection.count"
    ticks, xlabel = figures._cell_ticks([{"label": "case 1"}, {"label": "x" * 40}])
    assert xlabel is None and ticks[0] == "case 1" and len(ticks[1]) == 28


def test_distribution_legend_sits_above_the_panels(reported_run, tmp_path, monkeypatch):
    """Issue 31: the legend inside each panel hid the paper's case-2 values; it is one legend
    above the four panels, clear of them."""
    captured = []
    monkeypatch.setattr(figures, "_save", lambda fig, out_dir, name: captured.append(fig) or name)
    report_copy = tmp_path / "run"
    shutil.copytree(reported_run, report_copy)
    shutil.copy(os.path.join(reported_run, "trials.sqlite"),
                report_copy / "report" / "trials.snapshot.sqlite")
    figures.distribution_figure(figures.Run(str(report_copy)), str(tmp_path))
    fig = captured[0]
    assert all(ax.get_legend() is None for ax in fig.axes) and len(fig.legends) == 1
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    legend = fig.legends[0].get_window_extent(renderer)
    assert all(legend.y0 > ax.get_window_extent(renderer).y1 for ax in fig.axes)
