"""Simulates a calibration of the paper's arm, identifies it, and runs a small Monte-Carlo study.

    python3 examples/python/calibrate.py OUT_DIR
"""
import sys

import numpy as np

import lrcal

out_dir = sys.argv[1] if len(sys.argv) > 1 else "output/python-example"
robot = lrcal.Robot.load("paper")

# 101 candidate configurations whose beam hits the plane; choose 50 by E-optimality.
pool = lrcal.sample_configurations(robot, 101, seed=1)
design = lrcal.design(robot, pool, 50, criterion="E", method="exchange")
q = pool[design.indices]

# Ten noisy readings (σ = 0.2 mm) per configuration of the "true" arm, then identify.
readings = lrcal.simulate(robot, q, sigma_mm=0.2, repetitions=10, seed=1)
result = lrcal.identify(robot, readings.q, readings.h, sigma_mm=0.2)
print(result)

# The identified errors against the truth the simulation used, in mm and mrad.
truth = np.array([robot.true_errors[robot.value_names.index(n)] for n in result.names])
worst = np.max(np.abs(result.delta - truth) / result.std)
print(f"largest |estimate - truth| / std over {len(result.names)} parameters: {worst:.2f}")

# A Monte-Carlo study (the shipped 'quick' study), read back as pandas tables.
run = lrcal.run_study("quick", out_dir)
print(f"{run.done_before + run.computed} of {run.total} trials recorded in {out_dir}")
validation = lrcal.load_run(out_dir).tables["validation"]
rms = validation[(validation["model"] == "identified") & (validation["metric"] == "rms_pos")]
print(rms[["cell_label", "axis", "unit", "mean", "p95"]].to_string(index=False))
