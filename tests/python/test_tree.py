"""A tree's chains from Python (lrcal.Tree, identify_tree, Robot.load(base_link=)) against the
program's `--tool-link a,b` and `--base-link`: the same chains, the same fit."""
import csv
import json
import os

import numpy as np
import pytest

import lrcal

TRACKER = (2.5, 0.3, 0.2, 0.0, 0.0, 3.0)
TRACKER_ARG = "2.5,0.3,0.2,0,0,3"
HERE = os.path.dirname(os.path.abspath(__file__))
DUAL_ARM = os.path.join(HERE, "..", "..", "examples", "urdf", "dual_arm_torso.urdf")
HUMANOID = os.path.join(HERE, "..", "..", "examples", "urdf", "humanoid_like.urdf")


def read_points(path, joints):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return dict(sensor="point", instrument=TRACKER,
                q=np.array([[float(r[f"q{j + 1}"]) for j in range(joints)] for r in rows]),
                xyz=np.array([[float(r[c]) for c in "xyz"] for r in rows]),
                repetitions=[int(r["readings"]) for r in rows])


def test_a_chain_from_a_sole_runs_up_the_leg():
    robot = lrcal.Robot.load(HUMANOID, tool_link="left_gripper", base_link="left_sole")
    assert robot.num_joints == 14
    with pytest.raises(lrcal.InputError, match="no link named 'heel' \\(--base-link"):
        lrcal.Robot.load(HUMANOID, tool_link="left_gripper", base_link="heel")


def test_identify_tree_as_the_program(tmp_path, cli):
    tree = lrcal.Tree.load(DUAL_ARM, ["left_tool", "right_tool"])
    assert tree.tool_links == ["left_tool", "right_tool"]
    assert len(tree.joint_names) == 15 and tree.joint_names[:3] == [
        "torso_yaw", "torso_pitch_1", "torso_pitch_2"]
    assert [c.num_joints for c in tree.chains] == [9, 9]
    assert tree.link_labels[0][:3] == ["", "", "left_tool"]
    cli("design", "--robot", DUAL_ARM, "--tool-link", "left_tool,right_tool", "--sensor", "point",
        "--instrument", TRACKER_ARG, "--generate", "200", "--select", "25", "--method", "greedy",
        "--out", tmp_path / "whole.csv")
    parts = []
    for arm in ("left", "right"):
        cli("simulate", "--robot", DUAL_ARM, "--tool-link", f"{arm}_tool", "--sensor", "point",
            "--instrument", TRACKER_ARG, "--configs", tmp_path / "whole.csv", "--seed", "3",
            "--sigma-mm", "0.05", "--out", tmp_path / f"{arm}.csv")
        parts.append(read_points(tmp_path / f"{arm}.csv", 9))
    fit = lrcal.identify_tree(tree, parts, auto_fix=True, sigma_mm=0.05)
    done = cli("identify", "--robot", DUAL_ARM, "--tool-link", "left_tool,right_tool",
               "--sensor", "point", "--instrument", TRACKER_ARG, "--data", tmp_path / "left.csv",
               "--data", tmp_path / "right.csv", "--auto-fix", "--sigma-mm", "0.05",
               "--format", "json")
    program = json.loads(done.stdout[done.stdout.index("{"):done.stdout.rindex("}") + 1])
    assert fit.names == [p["name"] for p in program["parameters"]]
    assert "theta1" in fit.names and "left_tool.theta4" in fit.names
    np.testing.assert_allclose(fit.delta, [p["delta"] for p in program["parameters"]],
                               rtol=0, atol=1e-12)
    with pytest.raises(lrcal.InputError, match="expected one dict per chain of the tree \\(2\\)"):
        lrcal.identify_tree(tree, parts[:1])
    with pytest.raises(lrcal.InputError, match=r"parts\[1\]\.xyz"):
        lrcal.identify_tree(tree, [parts[0], dict(parts[1], xyz=parts[1]["xyz"][:3])])


def test_a_tree_study_runs_from_python_as_the_program_runs_it(tmp_path, cli):
    # The shipped dual-arm study, cut to 4 trials and smaller sets: the module and the program
    # write the same tables, and the pair's cell estimates each arm's own terms and the torso's
    # once.
    study = tmp_path / "dual.yaml"
    text = open(os.path.join(HERE, "..", "..", "studies", "dual_arm.yaml")).read()
    text = (text.replace("trials: 1000", "trials: 4")
                .replace("pool: {size: 200}", "pool: {size: 40}")
                .replace("validation: {size: 100}", "validation: {size: 10}")
                .replace("robot: ../examples", "robot: " + os.path.join(HERE, "..", "..",
                                                                        "examples")))
    study.write_text(text)
    lrcal.run_study(str(study), str(tmp_path / "module"), threads=2)
    cli("run", study, "--out", tmp_path / "program", "--threads", "1")
    tables = ["summary.json", "parameters.csv", "validation.csv"]
    for table in tables:
        assert (tmp_path / "module" / "tables" / table).read_text() == (
            tmp_path / "program" / "tables" / table).read_text(), table
    run = lrcal.load_run(str(tmp_path / "module"))
    summary = json.loads((tmp_path / "module" / "tables" / "summary.json").read_text())
    assert len(summary["cells"]) == 5
    parameters = (tmp_path / "module" / "tables" / "parameters.csv").read_text()
    assert "right_tool.theta9" in parameters and "left_tool.theta3" in parameters
    assert ",theta2," in parameters  # the torso's shared link, once
    assert run.trials["cell_id"].nunique() == 5 and len(run.trials) == 20


def test_a_robot_files_coupled_link_is_a_tree_of_one_chain():
    # couple: in a robot YAML file (q3 = -q2): one chain over five joints, as the program reads it.
    path = os.path.join(HERE, "..", "..", "examples", "robots", "parallelogram_arm.yaml")
    tree = lrcal.Tree.load(path, [])
    assert tree.joint_names == ["q1", "q2", "q4", "q5", "q6"]
    assert tree.tool_links == ["tool"]
    assert tree.chains[0].num_joints == 6
    with pytest.raises(lrcal.InputError, match="applies to a URDF robot"):
        lrcal.Tree.load(path, ["tool"])
