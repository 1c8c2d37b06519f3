"""Compliance and thermal growth from Python (issue 28): identify_in_environment and
identifiability_in_environment are `lrcal identify` and `lrcal identifiability` with
--estimate-compliance and --estimate-thermal, on the same simulated readings."""
import csv
import json
import os

import numpy as np

import lrcal

ROBOT = "studies/robots/paper_space.yaml"


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], np.array([[float(v) for v in r] for r in rows[1:]])


def test_identify_in_environment_is_the_programs(tmp_path, cli):
    robot_path = os.path.join(os.path.dirname(__file__), "..", "..", ROBOT)
    configs, env, data = tmp_path / "c.csv", tmp_path / "e.csv", tmp_path / "m.csv"
    cli("sample", "--robot", robot_path, "--count", 80, "--seed", 6, "--out", configs)
    header, q = read_csv(configs)
    with open(env, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header + ["gravity_x", "gravity_y", "gravity_z", "temperature_c"])
        for i, row in enumerate(q):
            w.writerow([repr(float(v)) for v in row] + [0, 0, -9.81, 0 if i % 2 else 40])
    cli("simulate", "--robot", robot_path, "--configs", env, "--sigma-mm", 0.005, "--seed", 2,
        "--out", data)
    program = json.loads(cli("identify", "--robot", robot_path, "--data", data, "--sigma-mm",
                             0.005, "--estimate-compliance", "j2,j3,j4,j5,j6",
                             "--estimate-thermal", "links", "--format", "json").stdout)
    header, m = read_csv(data)
    robot = lrcal.Robot.load(robot_path)
    gravity = m[:, [header.index(c) for c in ("gravity_x", "gravity_y", "gravity_z")]]
    result = lrcal.identify_in_environment(
        robot, m[:, :6], m[:, header.index("h")], gravity=gravity,
        temperature_c=m[:, header.index("temperature_c")], estimate_compliance="j2,j3,j4,j5,j6",
        estimate_thermal="links", sigma_mm=0.005)
    assert list(result.names) == [p["name"] for p in program["parameters"]]
    np.testing.assert_allclose(result.delta, [p["delta"] for p in program["parameters"]],
                               rtol=1e-9, atol=1e-15)
    c2 = list(result.names).index("c2")
    assert abs(result.delta[c2] - 10e-6) < 4 * result.std_given[c2]


def test_identifiability_in_environment_says_what_is_lost():
    robot = lrcal.Robot.load(os.path.join(os.path.dirname(__file__), "..", "..", ROBOT))
    q = lrcal.sample_configurations(robot, 50, seed=3)
    on_orbit = lrcal.identifiability_in_environment(
        robot, q, gravity=np.zeros((len(q), 3)), temperature_c=np.full(len(q), 20.0),
        estimate_compliance="all", estimate_thermal="links")
    assert {"c1", "c2", "c6", "thermal_links"} <= set(on_orbit.unidentifiable)
    words = " ".join(on_orbit.explanations)
    assert "c2: joint 2 carries no gravity torque" in words
    assert "every measurement at 20 °C" in words
