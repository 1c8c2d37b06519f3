"""One Python function per command, through the same library call as the program: the same
numbers, bit for bit, and the same checks (sample, kinematics, accuracy, export, plan,
replay_trial, status, report, merge, aggregate, paper; design and plan_accuracy are in test_calibration.py, run_study and load_run
in test_study.py)."""
import json
import os

import numpy as np
import pytest

import lrcal


def read_rows(path):
    with open(path) as f:
        lines = f.read().split()
    return np.array([[float(v) for v in line.split(",")] for line in lines[1:]])


def small_study(tmp_path, trials=6):
    path = tmp_path / "small.yaml"
    path.write_text(f"name: small\nseed: 2\ntrials: {trials}\nrobot: paper\n"
                    "pool: {size: 60}\nvalidation: {size: 5}\n"
                    "sweep:\n  axes:\n    - key: selection.count\n      values: [30, 59]\n")
    return str(path)


def test_sample_is_the_programs_sample(tmp_path, cli, paper):
    cli("sample", "--robot", "paper", "--count", 12, "--seed", 4, "--out", tmp_path / "q.csv")
    np.testing.assert_array_equal(lrcal.sample(paper, 12, seed=4), read_rows(tmp_path / "q.csv"))
    assert lrcal.sample is lrcal.sample_configurations


def test_kinematics_is_the_programs_kinematics(tmp_path, cli, paper):
    q = lrcal.sample(paper, 5, seed=8)
    np.savetxt(tmp_path / "q.csv", q, delimiter=",", header="q1,q2,q3,q4,q5,q6", comments="",
               fmt="%.17g")
    for model in ("nominal", "true"):
        program = json.loads(cli("kinematics", "--robot", "paper", "--configs", tmp_path / "q.csv",
                                 "--model", model, "--jacobian", "--estimate-ranger", "offset",
                                 "--format", "json").stdout)
        mine = lrcal.kinematics(paper, q, model=model, jacobian=True, estimate_ranger="offset")
        assert mine == program
    with pytest.raises(lrcal.InputError, match="outside the joint's range"):
        lrcal.kinematics(paper, np.degrees(q))
    with pytest.raises(lrcal.InputError, match="model"):
        lrcal.kinematics(paper, q, model="measured")


def test_accuracy_and_export_are_the_programs(tmp_path, cli, paper):
    q = lrcal.sample(paper, 40, seed=3)
    readings = lrcal.simulate(paper, q, sigma_mm=0.05, seed=3)
    rows = np.column_stack([readings.q, readings.h])
    np.savetxt(tmp_path / "m.csv", rows, delimiter=",", fmt="%.17g", comments="",
               header="q1,q2,q3,q4,q5,q6,h")
    cli("identify", "--robot", "paper", "--data", tmp_path / "m.csv", "--sigma-mm", 0.05,
        "--write-robot", tmp_path / "cal.yaml")
    calibrated = lrcal.Robot.load(str(tmp_path / "cal.yaml"))
    program = json.loads(cli("accuracy", "--robot", tmp_path / "cal.yaml", "--workspace", 30,
                             "--seed", 2, "--format", "json").stdout)
    assert lrcal.accuracy(calibrated, workspace=30, seed=2) == program
    with pytest.raises(lrcal.InputError, match="robot=: .* has no calibration record"):
        lrcal.accuracy(paper, workspace=5)
    with pytest.raises(lrcal.InputError, match="exactly one"):
        lrcal.accuracy(calibrated)
    for fmt in ("urdf", "dh-table", "yaml"):
        assert lrcal.export(calibrated, fmt) == cli("export", "--robot", tmp_path / "cal.yaml",
                                                    "--format", fmt).stdout
    with pytest.raises(lrcal.InputError, match="format=: expected urdf, dh-table or yaml"):
        lrcal.export(paper, "step")


def test_plan_replay_and_report_of_a_run(tmp_path, cli):
    study = small_study(tmp_path)
    plan = lrcal.plan(study, threads=2)
    program = json.loads(cli("plan", study, "--threads", 2, "--format", "json").stdout)
    assert [c["id"] for c in plan["cells"]] == [c["id"] for c in program["cells"]]
    assert plan["total_trials"] == program["total_trials"] == 12 and plan["threads"] == 2
    run = str(tmp_path / "run")
    lrcal.run_study(study, run, threads=2)
    cell = plan["cells"][1]["label"]
    replay = lrcal.replay_trial(run, cell, 3)
    program = json.loads(cli("trial", run, "--cell", cell, "--trial", 3, "--format", "json").stdout)
    text = replay.pop("text")
    assert replay == program and replay["identical"]
    assert "identical to the stored record, bit for bit" in text
    with pytest.raises(lrcal.InputError, match="trial=: expected 0 to 5, got 9"):
        lrcal.replay_trial(run, cell, 9)
    with pytest.raises(lrcal.InputError, match="cell=: no cell 'nope'"):
        lrcal.replay_trial(run, "nope", 0)
    status = lrcal.status(run)
    assert "text" in status and status.pop("text").startswith("study small in ")
    assert status == json.loads(cli("status", run, "--format", "json").stdout)
    assert status["complete"] and status["done"] == 12
    assert status["last_session"]["state"] == "completed"
    written = lrcal.report(run)
    assert written["complete"] and written["done"] == 12
    assert os.path.isfile(written["path"])
    assert not os.path.exists(os.path.join(run, "report", "trials.snapshot.sqlite"))
    with pytest.raises(lrcal.InputError):
        lrcal.report(str(tmp_path / "missing"))


def test_merge_and_aggregate_are_the_programs(tmp_path, cli):
    study = small_study(tmp_path, trials=4)
    shards = [str(tmp_path / f"shard{i}") for i in (1, 2)]
    lrcal.run_study(study, shards[0], threads=1, shard="1/2")
    partial = lrcal.merge(shards[:1], str(tmp_path / "partial"))
    program = cli("merge", shards[0], "--out", tmp_path / "partial_cli", check=False)
    assert program.returncode == 1 and not partial["complete"]
    assert "tables not written" in partial["text"] and "unfinished or missing shards: 2" in partial["text"]
    assert partial["status"]["done"] == 4 and partial["status"]["total"] == 8
    lrcal.run_study(study, shards[1], threads=1, shard="2/2")
    merged = lrcal.merge(shards, str(tmp_path / "merged"))
    cli("merge", *shards, "--out", tmp_path / "merged_cli")
    assert merged["complete"] and merged["status"]["complete"]
    assert merged["text"].endswith(f"tables: {tmp_path / 'merged'}/tables/summary.md\n")
    summary = (tmp_path / "merged" / "tables" / "summary.md").read_text()
    assert summary == (tmp_path / "merged_cli" / "tables" / "summary.md").read_text()
    os.remove(tmp_path / "merged" / "tables" / "summary.md")
    assert lrcal.aggregate(str(tmp_path / "merged")) == f"{tmp_path / 'merged'}/tables/summary.md"
    assert (tmp_path / "merged" / "tables" / "summary.md").read_text() == summary
    with pytest.raises(lrcal.InputError):
        lrcal.aggregate(str(tmp_path / "missing"))


def test_paper_is_the_programs_paper(cli, paper):
    ours = lrcal.paper(paper, seed=3, case1_selection="greedy")
    text = ours.pop("text")
    program = json.loads(cli("paper", "--seed", 3, "--case1-selection", "greedy",
                             "--format", "json").stdout)
    assert ours == program
    assert text == cli("paper", "--seed", 3, "--case1-selection", "greedy").stdout
    with pytest.raises(lrcal.InputError, match="samples=: expected"):
        lrcal.paper(paper, case1_selection="sampled", samples=0)
