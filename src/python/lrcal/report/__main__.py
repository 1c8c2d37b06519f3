"""python3 -m lrcal.report RUN_DIR | --calibration DIR: draws a report page (see lrcal.report).

Exit codes: 0 written; 2 a missing or malformed run directory or calibration.json (the message
names the file); 5 the page could not be written (a full disk, a folder that cannot be written).
"""
import sys

from . import calibration as _calibration
from . import figures as _figures
from . import page as _page

USAGE = "usage: python3 -m lrcal.report RUN_DIR | python3 -m lrcal.report --calibration DIR"


def main(argv):
    args = argv[1:]
    if args in ([], ["-h"], ["--help"]):
        print(USAGE, file=sys.stderr if not args else sys.stdout)
        return 2 if not args else 0
    calibration = args[0] == "--calibration"
    if calibration:
        args = args[1:]
    if len(args) != 1 or args[0].startswith("-"):
        print(f"lrcal.report: error: expected one folder; {USAGE}", file=sys.stderr)
        return 2
    try:
        path, figures = (_calibration.build if calibration else _page.build)(args[0])
    except (_figures.RunDataError, _calibration.CalibrationDataError) as e:
        print(f"lrcal.report: error: {e}", file=sys.stderr)
        return 2
    except OSError as e:
        print(f"lrcal.report: could not write the report: {e}", file=sys.stderr)
        return 5
    print(f"lrcal.report: {len(figures)} figures, {path}",
          file=sys.stderr if calibration else sys.stdout)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
