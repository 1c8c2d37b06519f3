"""Studies from Python: run_study gives the program's tables bit for bit, load_run reads them,
the GIL is released while trials run, Ctrl-C stops a run that then resumes to the same tables,
and errors carry the program's messages."""
import filecmp
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np
import pytest

import lrcal


def table_files(run_dir):
    tables = os.path.join(run_dir, "tables")
    return sorted(os.listdir(tables))


def assert_same_tables(a, b):
    names = table_files(a)
    assert names == table_files(b) and "validation.csv" in names
    match, mismatch, errors = filecmp.cmpfiles(os.path.join(a, "tables"),
                                               os.path.join(b, "tables"), names, shallow=False)
    assert not mismatch and not errors


def long_study(tmp_path, trials):
    """The quick study with more trials (a run of a second or more)."""
    path = tmp_path / "long.yaml"
    quick = os.path.join(lrcal.data_directory(), "studies", "quick.yaml")
    with open(quick) as f:
        text = f.read()
    lines = [f"trials: {trials}" if line.startswith("trials:") else line
             for line in text.splitlines()]
    lines = [f"robot: {os.path.join(lrcal.data_directory(), 'studies', 'robots', 'paper.yaml')}"
             if line.startswith("robot:") else line for line in lines]
    path.write_text("\n".join(lines) + "\n")
    return str(path)


def test_run_study_gives_the_programs_tables_and_trials(tmp_path, cli):
    cli("run", "quick", "--out", tmp_path / "cli", "--quiet")
    seen = []
    result = lrcal.run_study("quick", str(tmp_path / "py"), threads=2, progress=seen.append)
    assert result.complete and result.tables_written and result.computed == result.total == 200
    assert seen and seen[-1].done == seen[-1].total == 200
    assert seen[-1].eta_seconds == 0.0  # the ETA: nothing left at the end
    assert all(np.isnan(p.eta_seconds) or p.eta_seconds >= 0 for p in seen)
    assert_same_tables(tmp_path / "cli", tmp_path / "py")

    py_run, cli_run = lrcal.load_run(tmp_path / "py"), lrcal.load_run(tmp_path / "cli")
    assert len(py_run.trials) == 200
    columns = [c for c in py_run.trials.columns if c != "seconds"]  # wall time differs
    assert py_run.trials[columns].equals(cli_run.trials[columns])
    assert list(py_run.cells["label"]) == ["case 1", "case 2"]
    errors = py_run.errors("case 2")
    assert errors.shape == (100, 1 + len(py_run.cells["parameter_names"][1]))
    assert errors.dtypes.iloc[1] == np.float64
    assert set(py_run.tables) >= {"validation", "parameters", "cells"}
    assert py_run.summary is not None and py_run.manifest["study"]["name"] == "quick"
    # The trials in the tables' units, each column naming its unit: the mean of a cell's
    # val_rms_pos_x_mm is validation.csv's mean (6 decimals).
    validation = py_run.tables["validation"]
    for metric, unit in (("rms_pos", "mm"), ("max_ori", "mrad")):
        row = validation[(validation["cell_label"] == "case 1") &
                         (validation["model"] == "identified") &
                         (validation["metric"] == metric) & (validation["axis"] == "x")]
        assert row["unit"].item() == unit
        case1 = py_run.trials[py_run.trials["cell_id"] == row["cell_id"].item()]
        assert abs(case1[f"val_{metric}_x_{unit}"].mean() - row["mean"].item()) < 5e-7
    assert {"residual_rms_mm", "sigma_hat_mm", "nom_rms_ori_z_mrad"} <= set(py_run.trials.columns)
    assert (py_run.trials["missed_configurations"] == 0).all()  # the paper's beams all hit
    # One flat column per setting the study varies, in the cells frame and in cells.csv, with
    # numbers as numbers.
    cells = py_run.tables["cells"]
    for key, values in (("paper_case", [1, 2]), ("selection.count", [50, 100]),
                        ("selection.method", ["backward", "exhaustive"])):
        assert list(py_run.cells[key]) == list(cells[key]) == values
    assert cells["design_efficiency"].dtype == np.float64
    assert ((cells["design_efficiency"] > 0.99) & (cells["design_efficiency"] <= 1)).all()


def test_load_run_without_pandas_gives_numpy_structured_arrays(tmp_path):
    part = lrcal.run_study("quick", str(tmp_path / "r"), threads=1, max_trials=50)
    assert part.reached_max_trials and not part.complete and part.computed == 50
    assert not lrcal.load_run(tmp_path / "r").tables
    lrcal.run_study("quick", str(tmp_path / "r"), threads=1)
    run = lrcal.load_run(tmp_path / "r", as_pandas=False)
    assert isinstance(run.trials, np.ndarray) and run.trials.dtype.names[:3] == (
        "cell_id", "trial", "status")
    assert run.trials["residual_rms_mm"].dtype == np.float64 and len(run.trials) == 200
    assert run.tables["validation"]["n"].dtype == np.int64
    assert run.errors("case 1")["theta1"].shape == (100,)
    with pytest.raises(lrcal.InputError, match="no cell 'case 9'"):
        run.errors("case 9")


def test_load_run_reads_trials_by_cell_and_in_chunks(tmp_path):
    """trials_of and iter_trials give the rows of the whole trials table, a cell or a chunk at
    a time, without reading every trial: the trials table itself is read on first use."""
    first = lrcal.run_study("quick", str(tmp_path / "r"), threads=2)
    assert first.tables_written and not first.tables_current
    again = lrcal.run_study("quick", str(tmp_path / "r"), threads=2)
    assert again.computed == 0 and again.tables_written and again.tables_current
    run = lrcal.load_run(tmp_path / "r")
    assert run._trials is None and "200 trials" in repr(run)  # counted, not read
    every = run.trials
    case2 = run.trials_of("case 2")
    ids = list(run.cells["cell_id"])
    assert case2.equals(every[every["cell_id"] == ids[1]].reset_index(drop=True))
    assert list(run.trials_of(ids[0], 10, 13)["trial"]) == [10, 11, 12]
    chunks = list(run.iter_trials(chunk_size=30))
    assert [len(c) for c in chunks] == [30, 30, 30, 10] * 2
    import pandas as pd
    assert pd.concat(chunks, ignore_index=True).equals(every)
    assert [len(c) for c in run.iter_trials(["case 1"], chunk_size=64)] == [64, 36]
    with pytest.raises(ValueError, match="chunk_size"):
        next(run.iter_trials(chunk_size=0))
    with pytest.raises(lrcal.InputError, match="no cell 'case 9'"):
        run.trials_of("case 9")


def test_the_report_page_lists_a_large_studys_cells_in_cells_csv():
    from lrcal.report import page
    study = {"name": "s", "cells": [{"id": str(i), "label": str(i)} for i in range(25)]}
    assert page._settings(study)["cells"].startswith("25 cells: their ids, labels")
    study["cells"] = study["cells"][:24]
    assert page._settings(study) is study


def test_other_python_threads_run_while_trials_run(tmp_path):
    """The GIL is released around the trials: between two progress calls (0.1 s apart) the main
    thread keeps counting. With the GIL held it could not count at all between them."""
    study = long_study(tmp_path, 1500)
    counts, ticks = [0], []
    thread = threading.Thread(target=lambda: lrcal.run_study(
        study, str(tmp_path / "run"), threads=1, progress=lambda p: ticks.append(counts[0])))
    thread.start()
    while thread.is_alive():
        counts[0] += 1
        time.sleep(0.001)
    thread.join()
    gains = np.diff(ticks)
    assert len(gains) >= 3, "the study ended too fast to judge"
    assert np.median(gains) > 5, f"the main thread stalled while trials ran: {gains}"


def test_ctrl_c_stops_the_run_keeps_its_trials_and_it_resumes(tmp_path, cli):
    study = long_study(tmp_path, 3000)
    out = tmp_path / "run"
    script = textwrap.dedent(f"""
        import sys, lrcal
        def progress(p):
            if p.done > 0:
                print("started", flush=True)
        try:
            lrcal.run_study({study!r}, {str(out)!r}, threads=1, progress=progress)
        except KeyboardInterrupt:
            print("interrupted", flush=True)
            sys.exit(130)
        print("finished", flush=True)
    """)
    child = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True,
                             env=os.environ)
    assert child.stdout.readline().strip() == "started"
    child.send_signal(signal.SIGINT)
    rest = child.stdout.read()
    assert child.wait(timeout=120) == 130 and "interrupted" in rest
    partial = lrcal.load_run(out)
    assert 0 < len(partial.trials) < 6000 and not partial.tables
    assert partial.manifest["sessions"][-1]["ended"] == "interrupted"
    result = lrcal.run_study(study, str(out))
    assert result.complete and result.done_before == len(partial.trials)
    cli("run", study, "--out", tmp_path / "whole", "--quiet")
    assert_same_tables(out, tmp_path / "whole")


def test_an_exception_in_progress_stops_the_run_and_is_raised(tmp_path):
    def progress(p):
        raise RuntimeError("stop here")
    with pytest.raises(RuntimeError, match="stop here"):
        lrcal.run_study(long_study(tmp_path, 1000), str(tmp_path / "run"), progress=progress)
    assert lrcal.load_run(tmp_path / "run").manifest["sessions"][-1]["ended"] == "interrupted"


def test_errors_carry_the_programs_messages(tmp_path, cli, paper):
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: bad\ntrials: 10\nnoise: {sigma_mm: -1}\n")
    program = cli("run", bad, "--out", tmp_path / "x", check=False)
    assert program.returncode == 2
    with pytest.raises(lrcal.InputError) as raised:
        lrcal.run_study(str(bad), str(tmp_path / "y"))
    assert program.stderr.strip() == f"lrcal run: error: {raised.value}"
    assert isinstance(raised.value, ValueError) and isinstance(raised.value, lrcal.Error)
    assert raised.value.where.startswith(str(bad))

    with pytest.raises(lrcal.InputError, match="cannot open file") as raised:
        lrcal.Robot.load(str(tmp_path / "missing.yaml"))
    assert raised.value.where == str(tmp_path / "missing.yaml")
    q = lrcal.sample_configurations(paper, 30, seed=1)
    with pytest.raises(lrcal.InputError, match=r"q: expected an array of shape \(N, 6\)"):
        lrcal.identify(paper, q[:, :5], np.ones(30))
    with pytest.raises(lrcal.InputError, match="outside the ranger's range"):
        lrcal.identify(paper, q, np.full(30, 1000.0))
    with pytest.raises(lrcal.InputError, match="estimate_plane"):
        lrcal.identify(paper, q, lrcal.laser_readings(paper, q), estimate_plane="tilt")
    with pytest.raises(lrcal.InputError, match="fix: .*'a9'"):
        lrcal.identifiability(paper, q, fix=["a9"])
    with pytest.raises(lrcal.InputError, match="no manifest.json"):
        lrcal.load_run(tmp_path)
