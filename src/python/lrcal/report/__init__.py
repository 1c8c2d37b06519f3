"""lrcal.report: the report pages of lrcal, in Python.

    python3 -m lrcal.report RUN_DIR                 # a study run's page (what `lrcal report` runs)
    python3 -m lrcal.report --calibration DIR       # the page of `lrcal identify --report DIR`

`lrcal.report(run_dir)` (this package's `report`) prepares a study run's tables with the library,
then draws the page, as `lrcal report RUN_DIR` does. The drawing modules read only what lrcal
wrote, through lrcal.load_run's reader: `from lrcal.report import figures` gives the study
figures (Run, all_figures, ...), `page` the study page, `calibration` the calibration page.
They need pandas and matplotlib (Debian: python3-pandas, python3-matplotlib), not the compiled
module, so they also run where only the Python files are installed; they are imported only when
asked for, so `import lrcal` needs neither.
"""
import os
import subprocess
import sys


def report(run_dir):
    """Writes RUN_DIR/report/report.html (figures as PNG and SVG in RUN_DIR/report/figures/, the
    tables, the study settings, the manifest), partial or not, as `lrcal report RUN_DIR` does: the
    tables and the one-realisation data are prepared by the library, the figures are drawn by
    `python3 -m lrcal.report` with this interpreter (it needs pandas and matplotlib: Debian's
    python3-pandas, python3-matplotlib). Returns a dict: path (report.html), done and expected
    trials, complete, note. Raises lrcal.InputError for a missing or malformed run directory and
    lrcal.StorageError when the report cannot be written.
    """
    from .. import _lrcal  # the library prepares the tables: needs the compiled module
    run_dir = os.fspath(run_dir)
    data = _lrcal._prepare_report(run_dir)
    # The drawing runs in its own interpreter, so that matplotlib's backend (Agg) and state stay
    # out of the caller's; it imports this very package.
    package_parent = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([package_parent] + ([env["PYTHONPATH"]]
                                                            if env.get("PYTHONPATH") else []))
    try:
        done = subprocess.run([sys.executable, "-m", "lrcal.report", run_dir],
                              capture_output=True, text=True, check=False, env=env)
    finally:
        _lrcal._remove_report_snapshot(data["dir"])
    if done.returncode != 0:
        message = (done.stderr.strip() or done.stdout.strip() or
                   f"python3 -m lrcal.report failed (exit {done.returncode})")
        if done.returncode == 2:
            raise _lrcal.InputError(message)
        raise _lrcal.StorageError(message)
    return dict(path=os.path.join(data["dir"], "report.html"), **data)


__all__ = ["report"]
