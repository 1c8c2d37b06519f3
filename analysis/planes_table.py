"""The README's table for studies/planes.yaml, from what `lrcal run` wrote (RUN/tables/summary.json).

    /usr/bin/python3 analysis/planes_table.py output/planes

Each entry is the validation error of the identified model: the per-axis means over the trials
(the tables' 'RMS pos' and 'RMS ori', x, y, z) combined as sqrt(x^2 + y^2 + z^2), i.e. the RMS of
the 3-D error over the validation poses, in mm and mrad; one column per number of planes. Cells
are found by their settings, not their labels. Uses only the standard library.
"""
import json
import math
import sys


def setup_of(s):
    if s["identification"]["estimate_plane"] != "none":
        return "planes estimated (theta1, d1 fixed)"
    if s["identification"]["estimate_ranger"] != "none":
        return "ranger 0.3 mm 150 ppm, estimated (d6 fixed)"
    if s["truth"]["ranger_offset_mm"] != "robot_file":
        return "ranger 0.3 mm 150 ppm, not modelled"
    return "known planes"


def disturbance_of(s):
    n = s["noise"]
    if n["encoder_sigma_mrad"] > 0:
        return "encoder %g mrad" % n["encoder_sigma_mrad"]
    if n["outlier_fraction"] > 0:
        return "%g %% outliers" % (100 * n["outlier_fraction"])
    return "none"


def combined(cell, metric):
    v = cell["validation"]
    return math.sqrt(sum(v["%s_%s" % (metric, a)]["mean"] ** 2 for a in "xyz")) * 1e3


ROWS = [("known planes", "none", "none"), ("known planes", "encoder 0.05 mrad", "none"),
        ("known planes", "encoder 0.2 mrad", "none"), ("known planes", "2 % outliers", "none"),
        ("known planes", "2 % outliers", "huber"), ("known planes", "10 % outliers", "none"),
        ("known planes", "10 % outliers", "huber"),
        ("ranger 0.3 mm 150 ppm, not modelled", "none", "none"),
        ("ranger 0.3 mm 150 ppm, estimated (d6 fixed)", "none", "none"),
        ("planes estimated (theta1, d1 fixed)", "none", "none")]


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: planes_table.py RUN_DIR")
    path = sys.argv[1] + "/tables/summary.json"
    try:
        with open(path) as f:
            cells = json.load(f)["cells"]
    except (OSError, ValueError, KeyError) as e:
        sys.exit("planes_table.py: %s: expected lrcal's summary.json with 'cells' (%s)" % (path, e))
    table = {}
    for c in cells:
        s = c["settings"]
        key = (setup_of(s), disturbance_of(s), s["identification"]["loss"], len(s["plane"]))
        table[key] = c
    print("| set-up | disturbance | loss | 1 plane | 2 planes | 3 planes |")
    print("|---|---|---|---|---|---|")
    for setup, dist, loss in ROWS:
        row = []
        for n in (1, 2, 3):
            c = table.get((setup, dist, loss, n))
            if c is None:
                sys.exit("planes_table.py: no cell for %s, %s, %s, %d plane(s)" % (setup, dist, loss, n))
            fixed = " (fixed %s)" % ", ".join(c["fixed_for_rank"]) if c["fixed_for_rank"] else ""
            row.append("%.3f / %.3f%s" % (combined(c, "rms_pos"), combined(c, "rms_ori"), fixed))
        print("| %s | %s | %s | %s |" % (setup, dist, "Huber" if loss == "huber" else "least squares",
                                         " | ".join(row)))


if __name__ == "__main__":
    main()
