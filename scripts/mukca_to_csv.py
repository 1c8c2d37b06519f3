#!/usr/bin/env python3
"""Converts MUKCa's socket recordings into lrcal socket data files.

MUKCa (platonics-delft/kinematics_calibration, MIT) stores, per arm and per placement of its
two-socket tool, hole_0.csv and hole_1.csv: one row of seven joint angles (rad, no header) per
posture with the flange's ball seated in socket 0 or socket 1. lrcal reads one CSV per placement
with columns q1..q7 and socket (docs/FILE_FORMATS.md, "Socket data").

usage: scripts/mukca_to_csv.py MUKCA_DIR OUT_DIR [ARM/PLACEMENT ...]
(default: every placement of the arms lrcal ships, examples/mukca/README.md)
"""
import csv
import os
import sys

SHIPPED_ARMS = ["panda_1", "panda_2_clean", "panda_3", "panda_4_clean", "panda_6", "panda_7"]


def convert(mukca_dir, arm, placement, out_dir):
    rows = []
    for socket in (0, 1):
        path = os.path.join(mukca_dir, "data", arm, placement, "hole_%d.csv" % socket)
        with open(path, newline="") as f:
            for line_number, row in enumerate(csv.reader(f), start=1):
                if not row:
                    continue
                if len(row) != 7:
                    sys.exit("%s:%d: expected 7 joint angles, got %d" % (path, line_number, len(row)))
                rows.append([float(v) for v in row] + [socket])
    name = "%s_%s.csv" % (arm, placement.replace("-", "_"))
    with open(os.path.join(out_dir, name), "w", newline="") as f:
        out = csv.writer(f, lineterminator="\n")
        out.writerow(["q%d" % j for j in range(1, 8)] + ["socket"])
        for row in rows:
            out.writerow([repr(v) for v in row[:7]] + [row[7]])
    return name, len(rows)


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    mukca_dir, out_dir = sys.argv[1], sys.argv[2]
    pairs = [p.split("/", 1) for p in sys.argv[3:]]
    if not pairs:
        for arm in SHIPPED_ARMS:
            for placement in sorted(os.listdir(os.path.join(mukca_dir, "data", arm))):
                pairs.append([arm, placement])
    os.makedirs(out_dir, exist_ok=True)
    for arm, placement in pairs:
        name, count = convert(mukca_dir, arm, placement, out_dir)
        print("%s: %d seatings" % (name, count))


if __name__ == "__main__":
    main()
