"""lrcal.report: the figures and report.html of a run, as `lrcal report RUN_DIR` writes them."""
import os
import subprocess
import sys

from . import _lrcal


def report(run_dir):
    """Writes RUN_DIR/report/report.html (figures as PNG and SVG in RUN_DIR/report/figures/, the
    tables, the study settings, the manifest), partial or not, as `lrcal report RUN_DIR` does: the
    tables and the one-realisation data are prepared by the library, the figures are drawn by
    lrcal's analysis/report.py with this interpreter (it needs pandas and matplotlib: Debian's
    python3-pandas, python3-matplotlib). Returns a dict: path (report.html), done and expected
    trials, complete, note. Raises lrcal.InputError for a missing or malformed run directory and
    lrcal.StorageError when the report cannot be written.
    """
    run_dir = os.fspath(run_dir)
    data = _lrcal._prepare_report(run_dir)
    script = os.path.join(_lrcal.data_directory(), "analysis", "report.py")
    try:
        done = subprocess.run([sys.executable, script, run_dir], capture_output=True, text=True,
                              check=False)
    finally:
        _lrcal._remove_report_snapshot(data["dir"])
    if done.returncode != 0:
        message = (done.stderr.strip() or done.stdout.strip() or
                   f"analysis/report.py failed (exit {done.returncode})")
        if done.returncode == 2:
            raise _lrcal.InputError(message)
        raise _lrcal.StorageError(message)
    return dict(path=os.path.join(data["dir"], "report.html"), **data)
