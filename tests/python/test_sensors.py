"""The tracker kinds from Python (lrcal.identifiability(sensor=), simulate_tracker,
identify_tracker) against the program's `--sensor point|pose`: the same counts, the same
simulated values bit for bit, the same fit."""
import csv
import os
import json

import numpy as np
import pytest

import lrcal

TRACKER = (2.5, 0.3, 0.2, 0.0, 0.0, 3.0)
TRACKER_ARG = "2.5,0.3,0.2,0,0,3"


def write_configurations(path, q, column=None, values=()):
    """Writes configurations q (N, 6) as the program reads them, exactly (repr), with an optional
    extra column (socket, plane) of one value per configuration."""
    with open(path, "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow([f"q{j + 1}" for j in range(6)] + ([column] if column else []))
        if column:
            writer.writerows([[repr(v) for v in row] + [x] for row, x in zip(q, values)])
        else:
            writer.writerows([[repr(v) for v in row] for row in q])


def test_identifiability_counts_the_slides_and_everetts_terms(paper):
    q = lrcal.sample_configurations(paper, 40, seed=3)
    assert lrcal.identifiability(paper, q).rank == 25
    point = lrcal.identifiability(paper, q, sensor="point", instrument=TRACKER)
    assert (point.rank, len(point.names)) == (27, 34)
    pose = lrcal.identifiability(paper, q, sensor="pose", instrument=TRACKER)
    assert (pose.rank, len(pose.names)) == (30, 37)
    two = lrcal.identifiability(paper, q, sensor="pose", instrument=TRACKER,
                                targets=[(0, 0, 0.1), (0.05, 0, 0.1, 0, 0.5, 0)],
                                target_of=[1 + i % 2 for i in range(40)])
    assert (two.rank, len(two.names)) == (36, 43)


def test_simulated_values_match_the_program_bit_for_bit_and_calibrate(tmp_path, cli, paper):
    q = lrcal.sample_configurations(paper, 40, seed=3)
    configs = tmp_path / "c.csv"
    write_configurations(configs, q)
    cli("simulate", "--sensor", "pose", "--configs", configs, "--instrument", TRACKER_ARG,
        "--sigma-mm", "0.05", "--sigma-mrad", "0.1", "--repetitions", "3", "--seed", "9",
        "--out", tmp_path / "m.csv")
    sim = lrcal.simulate_tracker(paper, q, sensor="pose", instrument=TRACKER, sigma_mm=0.05,
                                 sigma_mrad=0.1, repetitions=3, seed=9)
    with open(tmp_path / "m.csv") as f:
        rows = list(csv.DictReader(f))
    xyz = np.array([[float(r[c]) for c in "xyz"] for r in rows])
    quaternion = np.array([[float(r[c]) for c in ("qx", "qy", "qz", "qw")] for r in rows])
    np.testing.assert_array_equal(sim["xyz"], xyz)
    # Written with 17 digits; the sign of a quaternion is free.
    np.testing.assert_allclose(np.abs(np.sum(sim["quaternion"] * quaternion, axis=1)), 1.0,
                               atol=1e-12)
    assert list(sim["repetitions"]) == [3] * 40

    fit = lrcal.identify_tracker(paper, sim["q"], sim["xyz"], sensor="pose",
                                 quaternion=sim["quaternion"], instrument=TRACKER,
                                 repetitions=sim["repetitions"], auto_fix=True, sigma_mm=0.05,
                                 sigma_mrad=0.1)
    done = cli("identify", "--sensor", "pose", "--data", tmp_path / "m.csv", "--instrument",
               TRACKER_ARG, "--auto-fix", "--sigma-mm", "0.05", "--sigma-mrad", "0.1",
               "--format", "json")
    program = json.loads(done.stdout)
    assert fit.names == [p["name"] for p in program["parameters"]]
    np.testing.assert_allclose(fit.delta, [p["delta"] for p in program["parameters"]],
                               rtol=0, atol=1e-12)
    assert fit.holdout is None

    # holdout=4: the program's --holdout 4, every value of every held-out pose.
    fit = lrcal.identify_tracker(paper, sim["q"], sim["xyz"], sensor="pose",
                                 quaternion=sim["quaternion"], instrument=TRACKER,
                                 repetitions=sim["repetitions"], auto_fix=True, sigma_mm=0.05,
                                 sigma_mrad=0.1, holdout=4)
    done = cli("identify", "--sensor", "pose", "--data", tmp_path / "m.csv", "--instrument",
               TRACKER_ARG, "--auto-fix", "--sigma-mm", "0.05", "--sigma-mrad", "0.1",
               "--holdout", "4", "--format", "json")
    held_out = json.loads(done.stdout)["holdout"]
    assert len(fit.holdout["predictions"]) == 240
    assert [p["component"] for p in fit.holdout["predictions"][:6]] == list(range(6))
    np.testing.assert_allclose([p["error"] for p in fit.holdout["predictions"]],
                               [p["error"] for p in held_out["predictions"]], rtol=0, atol=1e-12)
    assert fit.holdout["ratio_angle"] == pytest.approx(held_out["ratio_angle"], abs=1e-9)
    with pytest.raises(lrcal.InputError, match="holdout"):
        lrcal.identify_tracker(paper, sim["q"], sim["xyz"], sensor="pose",
                               quaternion=sim["quaternion"], instrument=TRACKER, holdout=1)

    # predict_at=poses: the program's --predict-at, the calibrated arm's accuracy at the poses.
    poses = lrcal.sample_configurations(paper, 6, seed=8)
    write_configurations(tmp_path / "p.csv", poses)
    fit = lrcal.identify_tracker(paper, sim["q"], sim["xyz"], sensor="pose",
                                 quaternion=sim["quaternion"], instrument=TRACKER,
                                 repetitions=sim["repetitions"], auto_fix=True, sigma_mm=0.05,
                                 sigma_mrad=0.1, predict_at=poses)
    done = cli("identify", "--sensor", "pose", "--data", tmp_path / "m.csv", "--instrument",
               TRACKER_ARG, "--auto-fix", "--sigma-mm", "0.05", "--sigma-mrad", "0.1",
               "--predict-at", tmp_path / "p.csv", "--format", "json")
    stated = json.loads(done.stdout)["accuracy"]
    assert len(fit.accuracy["poses"]) == 6
    for mine, theirs in zip(fit.accuracy["poses"], stated["poses"]):
        assert mine["position_radius_95_total"] == pytest.approx(
            theirs["position_radius_95_total"], rel=1e-9)
        assert mine["position_radius_95"] > 0
    assert fit.holdout is None


def test_noise_free_tracker_data_give_the_true_errors(paper):
    q = lrcal.sample_configurations(paper, 40, seed=3)
    sim = lrcal.simulate_tracker(paper, q, sensor="point", instrument=TRACKER, sigma_mm=0,
                                 repetitions=1)
    fit = lrcal.identify_tracker(paper, sim["q"], sim["xyz"], instrument=TRACKER, auto_fix=True)
    delta = dict(zip(fit.names, fit.delta))
    assert delta["theta1"] == pytest.approx(-7.23e-3, abs=1e-9)
    assert delta["a2"] == pytest.approx(1.94e-3, abs=1e-9)


def test_bad_tracker_arguments_are_named(paper):
    q = lrcal.sample_configurations(paper, 5, seed=3)
    with pytest.raises(lrcal.InputError, match="estimate_plane: is the ranger's"):
        lrcal.identifiability(paper, q, sensor="point", estimate_plane="normal")
    with pytest.raises(lrcal.InputError, match="instrument: is a tracker's"):
        lrcal.identifiability(paper, q, instrument=TRACKER)
    with pytest.raises(lrcal.InputError, match="'scanner' is not a tracker"):
        lrcal.simulate_tracker(paper, q, sensor="scanner")
    sim = lrcal.simulate_tracker(paper, q, sensor="pose", repetitions=1)
    with pytest.raises(lrcal.InputError, match=r"quaternion\[0\]: expected a unit quaternion"):
        lrcal.identify_tracker(paper, sim["q"], sim["xyz"], sensor="pose",
                               quaternion=2 * sim["quaternion"])
    with pytest.raises(lrcal.InputError, match=r"xyz: expected an array of shape \(5, 3\)"):
        lrcal.identify_tracker(paper, sim["q"], sim["xyz"][:4])
    with pytest.raises(lrcal.InputError, match="target_of: 2 targets"):
        lrcal.identifiability(paper, q, sensor="point", targets=[(0, 0, 0), (0, 0, 0.1)])


SOCKETS = [(0.8, 0.3, 0.4), (0.8, 0.35, 0.4)]


def test_sockets_simulate_identify_and_judge_as_the_program(tmp_path, cli, paper):
    q = lrcal.sample_configurations(paper, 40, seed=3)
    socket_of = [i % 2 for i in range(40)]
    starts = tmp_path / "s.csv"
    write_configurations(starts, q, "socket", socket_of)
    cli("simulate", "--sensor", "socket", "--configs", starts, "--socket", "0.8,0.3,0.4",
        "--socket", "0.8,0.35,0.4", "--sigma-mm", "0.1", "--seed", "4",
        "--out", tmp_path / "seated.csv")
    sim = lrcal.simulate_sockets(paper, q, socket_of, SOCKETS, sigma_mm=0.1, seed=4)
    with open(tmp_path / "seated.csv") as f:
        rows = list(csv.DictReader(f))
    seated = np.array([[float(r[f"q{j + 1}"]) for j in range(6)] for r in rows])
    np.testing.assert_array_equal(sim["q"], seated)
    assert list(sim["socket_of"]) == [int(r["socket"]) for r in rows]
    assert sim["misses"].count("ok") == len(rows)

    distances = [(0, 1, 0.05)]
    analysis = lrcal.identifiability(paper, sim["q"], sensor="socket",
                                     socket_of=sim["socket_of"], socket_distances=distances)
    assert (analysis.rank, len(analysis.names)) == (26, 33)
    fit = lrcal.identify_sockets(paper, sim["q"], sim["socket_of"], socket_distances=distances,
                                 auto_fix=True, sigma_mm=0.1)
    done = cli("identify", "--sensor", "socket", "--data", tmp_path / "seated.csv",
               "--socket-distance", "0,1=0.05", "--auto-fix", "--sigma-mm", "0.1",
               "--format", "json")
    program = json.loads(done.stdout)
    assert fit.names == [p["name"] for p in program["parameters"]]
    np.testing.assert_allclose(fit.delta, [p["delta"] for p in program["parameters"]],
                               rtol=0, atol=1e-12)

    judged = lrcal.socket_consistency(paper, sim["q"], sim["socket_of"],
                                      socket_distances=distances)
    done = cli("accuracy", "--robot", "paper", "--sockets", tmp_path / "seated.csv",
               "--socket-distance", "0,1=0.05", "--format", "json")
    program = json.loads(done.stdout)
    assert judged["rms_spread"] == pytest.approx(program["rms_spread"], abs=1e-15)
    assert judged["distances"][0]["error"] == pytest.approx(program["distances"][0]["error"],
                                                            abs=1e-15)
    with pytest.raises(lrcal.InputError, match="socket_distances\\[0\\]"):
        lrcal.identify_sockets(paper, sim["q"], sim["socket_of"], socket_distances=[(0, 0, 0.05)])
    with pytest.raises(lrcal.InputError, match="socket_of: is the socket sensor's"):
        lrcal.identifiability(paper, sim["q"], socket_of=sim["socket_of"])


PLANES = [lrcal.Plane([0.1, 0.2, 1.0], -0.3), lrcal.Plane([1.0, 0.0, 0.2], -0.9)]


def test_contacts_simulate_and_identify_as_the_program(tmp_path, cli, paper):
    q = lrcal.sample_configurations(paper, 40, seed=3)
    plane_of = [1 + i % 2 for i in range(40)]
    starts = tmp_path / "s.csv"
    write_configurations(starts, q, "plane", plane_of)
    planes = ["--plane", "0.1,0.2,1,-0.3", "--plane", "1,0,0.2,-0.9"]
    cli("simulate", "--sensor", "contact", "--flush", "--configs", starts, *planes,
        "--sigma-mm", "0.02", "--sigma-mrad", "0.1", "--seed", "4",
        "--out", tmp_path / "contacts.csv")
    sim = lrcal.simulate_contacts(paper, q, plane=PLANES, plane_of=plane_of, flush=True,
                                  sigma_mm=0.02, sigma_mrad=0.1, seed=4)
    with open(tmp_path / "contacts.csv") as f:
        rows = list(csv.DictReader(f))
    np.testing.assert_array_equal(sim["q"], [[float(r[f"q{j + 1}"]) for j in range(6)]
                                             for r in rows])
    assert list(sim["plane_of"]) == [int(r["plane"]) for r in rows]
    assert {r["flush"] for r in rows} == {"1"}

    fit = lrcal.identify_contacts(paper, sim["q"], plane=PLANES, plane_of=sim["plane_of"],
                                  flush=True, estimate_plane="normal,offset", auto_fix=True,
                                  sigma_mm=0.02, sigma_mrad=0.1)
    done = cli("identify", "--sensor", "contact", "--data", tmp_path / "contacts.csv", *planes,
               "--estimate-plane", "normal,offset", "--auto-fix", "--sigma-mm", "0.02",
               "--sigma-mrad", "0.1", "--format", "json")
    program = json.loads(done.stdout)
    assert fit.names == [p["name"] for p in program["parameters"]]
    np.testing.assert_allclose(fit.delta, [p["delta"] for p in program["parameters"]],
                               rtol=0, atol=1e-12)
    for key in ("excess", "holds", "pairs"):
        assert fit.linearisation[key] == pytest.approx(program["linearisation"][key], rel=1e-9)
    with pytest.raises(lrcal.InputError, match="estimate_plane"):
        lrcal.identify_contacts(paper, sim["q"], plane=PLANES, plane_of=sim["plane_of"],
                                estimate_plane="tilt")

    # What the contacts identify, as `lrcal identifiability --sensor contact` says (the seated
    # postures without the flush column for point contacts).
    point_contacts = tmp_path / "point.csv"
    write_configurations(point_contacts, sim["q"], "plane", sim["plane_of"])
    counts = []
    for flush, data in ((False, point_contacts), (True, tmp_path / "contacts.csv")):
        analysis = lrcal.identifiability(paper, sim["q"], sensor="contact", plane=PLANES,
                                         plane_of=sim["plane_of"], flush=flush,
                                         estimate_plane="normal,offset")
        done = cli("identifiability", "--sensor", "contact", "--configs", data, *planes,
                   "--estimate-plane", "normal,offset", "--format", "json")
        program = json.loads(done.stdout)
        assert analysis.rank == program["rank"]
        assert analysis.suggested_fixed == program["suggested_fixed"]
        counts.append((analysis.rank, len(analysis.names)))
    # The README's counts: flush contacts are analysed at postures squared to their planes.
    assert counts == [(26, 34), (24, 34)]
    with pytest.raises(lrcal.InputError, match="flush: is the contact sensor's"):
        lrcal.identifiability(paper, sim["q"], flush=True)
    with pytest.raises(lrcal.InputError, match="socket_of: is the contact sensor's|socket_of"):
        lrcal.identifiability(paper, sim["q"], sensor="contact", plane=PLANES,
                              plane_of=sim["plane_of"], socket_of=sim["plane_of"])


def test_scanner_simulate_identify_and_identifiability_as_the_program(tmp_path, cli, paper):
    q = lrcal.sample_configurations(paper, 40, seed=3)
    starts = tmp_path / "c.csv"
    write_configurations(starts, q)
    frame = (0.03, -0.01, 0.02, 0.1, 0.2, 0.3)
    geometry = ["--sensor", "scanner", "--beams", "5", "--fan-deg", "10",
                "--scanner", ",".join(repr(v) for v in frame)]
    cli("simulate", *geometry, "--configs", starts, "--sigma-mm", "0.05", "--repetitions", "3",
        "--seed", "4", "--out", tmp_path / "scans.csv")
    sim = lrcal.simulate_scanner(paper, q, beams=5, fan_deg=10, scanner=frame, sigma_mm=0.05,
                                 repetitions=3, seed=4)
    with open(tmp_path / "scans.csv") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 5 * len(sim["q"])
    np.testing.assert_array_equal(sim["h"].ravel(), [float(r["h"]) for r in rows])
    assert sim["repetitions"] == [3] * len(sim["q"])
    assert len(sim["misses"]) == 40
    assert sum(m == "ok" for m in sim["misses"]) == len(sim["q"])

    fit = lrcal.identify_scanner(paper, sim["q"], sim["h"], fan_deg=10, scanner=frame,
                                 estimate_plane="normal,offset", repetitions=sim["repetitions"],
                                 auto_fix=True, sigma_mm=0.05)
    done = cli("identify", *geometry, "--data", tmp_path / "scans.csv", "--estimate-plane",
               "normal,offset", "--auto-fix", "--sigma-mm", "0.05", "--format", "json")
    program = json.loads(done.stdout)
    assert fit.names == [p["name"] for p in program["parameters"]]
    np.testing.assert_allclose(fit.delta, [p["delta"] for p in program["parameters"]],
                               rtol=0, atol=1e-12)
    assert fit.linearisation["holds"] == program["linearisation"]["holds"]

    analysis = lrcal.identifiability(paper, sim["q"], sensor="scanner", beams=5, fan_deg=10,
                                     scanner=frame, estimate_plane="normal,offset")
    done = cli("identifiability", *geometry, "--configs", tmp_path / "scans.csv",
               "--estimate-plane", "normal,offset", "--format", "json")
    program = json.loads(done.stdout)
    assert (analysis.rank, len(analysis.names)) == (program["rank"], program["n_params"])
    assert analysis.suggested_fixed == program["suggested_fixed"]
    with pytest.raises(lrcal.InputError, match="beams: is the scanner sensor's"):
        lrcal.identifiability(paper, sim["q"], beams=5)
    with pytest.raises(lrcal.InputError, match="h: expected an \\(N, beams\\) array"):
        lrcal.identify_scanner(paper, sim["q"], sim["h"].ravel())


def test_scanner_geometry_out_of_range_is_an_error_naming_the_argument(paper):
    q = lrcal.sample_configurations(paper, 5, seed=3)
    with pytest.raises(lrcal.InputError, match="beams: expected 1 to 256 beams, got 0"):
        lrcal.simulate_scanner(paper, q, beams=0)
    with pytest.raises(lrcal.InputError, match="beams: expected 1 to 256 beams, got 257"):
        lrcal.identifiability(paper, q, sensor="scanner", beams=257)
    with pytest.raises(lrcal.InputError,
                       match="fan_deg: expected a half angle from 0 to below 90 deg, got 90"):
        lrcal.simulate_scanner(paper, q, beams=3, fan_deg=90)
    with pytest.raises(lrcal.InputError, match="fan_deg: .* got -1"):
        lrcal.identifiability(paper, q, sensor="scanner", beams=3, fan_deg=-1)


def test_tracker_design_is_the_programs(tmp_path, cli, paper):
    q = lrcal.sample_configurations(paper, 60, seed=3)
    pool = tmp_path / "c.csv"
    write_configurations(pool, q)
    design = lrcal.design(paper, q, 12, method="backward", baseline=50, sensor="pose",
                          instrument=TRACKER)
    done = cli("design", "--pool", pool, "--select", "12", "--method", "backward",
               "--baseline", "50", "--sensor", "pose", "--instrument", TRACKER_ARG,
               "--format", "json")
    program = json.loads(done.stdout)
    assert design.sensor == "pose"
    assert design.held_at_nominal == program["held_at_nominal"]
    assert len(design.held_at_nominal) == 7
    assert design.indices == program["selected"]
    assert design.efficiency is None
    with pytest.raises(lrcal.InputError, match="estimate_plane: is the ranger's"):
        lrcal.design(paper, q, 12, sensor="point", instrument=TRACKER, estimate_plane="offset")
    with pytest.raises(lrcal.InputError, match="instrument: is a tracker's"):
        lrcal.design(paper, q, 12, instrument=TRACKER)


def test_scanner_contact_and_socket_designs_are_the_programs(tmp_path, cli, paper):
    """design(sensor=) chooses from the candidates where the kind measures, as `lrcal design
    --sensor` does from the same pool file: the same held terms and the same rows (the
    program's indices count its usable candidates; the module's are rows of the pool)."""
    q = lrcal.sample_configurations(paper, 60, seed=3)
    pool = tmp_path / "c.csv"
    write_configurations(pool, q)
    socket_of = [i % 2 for i in range(60)]
    seated = lrcal.simulate_sockets(paper, q, socket_of, SOCKETS, sigma_mm=0, seed=4)
    sockets = tmp_path / "k.csv"
    write_configurations(sockets, seated["q"], "socket", seated["socket_of"])
    cases = [
        (q, pool, dict(sensor="scanner", beams=5, fan_deg=10),
         ["--sensor", "scanner", "--beams", "5", "--fan-deg", "10"]),
        (q, pool, dict(sensor="contact", tool_point=(0, 0, 0.05)),
         ["--sensor", "contact", "--target", "0,0,0.05"]),
        (seated["q"], sockets,
         dict(sensor="socket", socket_of=seated["socket_of"], tool_point=(0, 0, 0.05),
              socket_distances=[(0, 1, 0.05)]),
         ["--sensor", "socket", "--target", "0,0,0.05", "--socket-distance", "0,1=0.05"]),
    ]
    for rows, path, kwargs, args in cases:
        design = lrcal.design(paper, rows, 25, method="backward", baseline=50, **kwargs)
        done = cli("design", "--pool", path, "--select", "25", "--method", "backward",
                   "--baseline", "50", *args, "--format", "json")
        program = json.loads(done.stdout[done.stdout.index("{"):])
        assert design.sensor == kwargs["sensor"]
        assert design.held_at_nominal == program["held_at_nominal"], kwargs["sensor"]
        left_out = {row for row, _ in design.rejected}
        kept = [i for i in range(len(rows)) if i not in left_out]
        assert design.indices == [kept[i] for i in program["selected"]], kwargs["sensor"]
    scanner = lrcal.design(paper, q, 25, sensor="scanner", beams=5, fan_deg=10)
    assert scanner.rejected and all("beam" in why for _, why in scanner.rejected)
    with pytest.raises(lrcal.InputError, match="beams: is the scanner sensor's"):
        lrcal.design(paper, q, 12, sensor="contact", beams=5)
    with pytest.raises(lrcal.InputError, match="socket_of: is the socket sensor's"):
        lrcal.design(paper, q, 12, sensor="scanner", socket_of=socket_of)
    with pytest.raises(lrcal.InputError, match="sensor: 'sonar' is not a sensor"):
        lrcal.design(paper, q, 12, sensor="sonar")


def test_mixed_kinds_identify_as_the_program_and_recover_the_truth(tmp_path, cli, paper):
    q = lrcal.sample_configurations(paper, 40, seed=3)
    plane_of = [1 + i % 2 for i in range(40)]
    configs, starts = tmp_path / "c.csv", tmp_path / "s.csv"
    write_configurations(configs, q)
    write_configurations(starts, q, "plane", plane_of)
    planes = ["--plane", "0.1,0.2,1,-0.3", "--plane", "1,0,0.2,-0.9"]
    cli("simulate", "--sensor", "pose", "--configs", configs, "--instrument", TRACKER_ARG,
        "--sigma-mm", "0.05", "--sigma-mrad", "0.1", "--repetitions", "3", "--seed", "9",
        "--out", tmp_path / "poses.csv")
    cli("simulate", "--sensor", "contact", "--flush", "--configs", starts, *planes,
        "--target", "0.01,0,0.1", "--sigma-mm", "0.05", "--sigma-mrad", "0.1", "--seed", "4",
        "--out", tmp_path / "contacts.csv")
    poses = lrcal.simulate_tracker(paper, q, sensor="pose", instrument=TRACKER, sigma_mm=0.05,
                                   sigma_mrad=0.1, repetitions=3, seed=9)
    contacts = lrcal.simulate_contacts(paper, q, plane=PLANES, plane_of=plane_of, flush=True,
                                       tool_point=[0.01, 0, 0.1], sigma_mm=0.05,
                                       sigma_mrad=0.1, seed=4)
    parts = [dict(sensor="pose", q=poses["q"], xyz=poses["xyz"],
                  quaternion=poses["quaternion"], instrument=TRACKER,
                  repetitions=poses["repetitions"]),
             dict(sensor="contact", q=contacts["q"], plane=PLANES,
                  plane_of=contacts["plane_of"], tool_point=[0.01, 0, 0.1], flush=True,
                  estimate_plane="normal,offset")]
    fit = lrcal.identify_mixed(paper, parts, auto_fix=True, sigma_mm=0.05, sigma_mrad=0.1)
    done = cli("identify", "--sensor", "pose,contact", "--data", tmp_path / "poses.csv",
               "--data", tmp_path / "contacts.csv", "--instrument", TRACKER_ARG, *planes,
               "--probe", "0.01,0,0.1", "--estimate-plane", "normal,offset", "--auto-fix",
               "--sigma-mm", "0.05", "--sigma-mrad", "0.1", "--format", "json")
    program = json.loads(done.stdout)
    assert program["sensor"] == "mixed"
    assert [p["sensor"] for p in program["parts"]] == ["pose", "contact"]
    assert fit.names == [p["name"] for p in program["parameters"]]
    assert "contact.target_z" in fit.names
    np.testing.assert_allclose(fit.delta, [p["delta"] for p in program["parameters"]],
                               rtol=0, atol=1e-12)

    # Noise-free, the union returns the robot file's true errors.
    exact = lrcal.simulate_tracker(paper, q, sensor="point", instrument=TRACKER, sigma_mm=0)
    seated = lrcal.simulate_contacts(paper, q, plane=PLANES, plane_of=plane_of, flush=True,
                                     tool_point=[0.01, 0, 0.1], sigma_mm=0, sigma_mrad=0)
    fit = lrcal.identify_mixed(
        paper,
        [dict(sensor="point", q=exact["q"], xyz=exact["xyz"], instrument=TRACKER),
         dict(sensor="contact", q=seated["q"], plane=PLANES, plane_of=seated["plane_of"],
              tool_point=[0.01, 0, 0.1], flush=True)],
        auto_fix=True)
    delta = dict(zip(fit.names, fit.delta))
    assert delta["beta2"] == pytest.approx(1.45e-3, abs=1e-9)
    assert delta["alpha5"] == pytest.approx(-4.83e-3, abs=1e-9)

    with pytest.raises(lrcal.InputError, match=r"parts\[1\]\.h: missing"):
        lrcal.identify_mixed(paper, [parts[0], dict(sensor="scanner", q=q)])
    with pytest.raises(lrcal.InputError, match=r"parts\[0\]\.plane_of: is not an argument"):
        lrcal.identify_mixed(paper, [dict(parts[0], plane_of=plane_of)])
    with pytest.raises(lrcal.InputError, match="'laser' is not a kind identify_mixed takes"):
        lrcal.identify_mixed(paper, [dict(sensor="laser", q=q)])


def test_compensate_as_the_program_and_reaches_the_plans(tmp_path, cli):
    panda = "examples/mukca/panda.urdf"
    root = os.path.join(os.path.dirname(__file__), "..", "..")
    urdf = os.path.join(root, panda)
    cli("identify", "--sensor", "socket", "--robot", urdf, "--tool-link", "ball_link",
        "--socket-distance", "0,1=0.05", "--fix", "target_x,target_y,target_z", "--auto-fix",
        "--sigma-mm", "0.3", "--prior-sigma", "theta=10mrad,alpha=10mrad,a=2mm,d=2mm",
        "--data", os.path.join(root, "examples/mukca/panda_1_front.csv"),
        "--write-robot", tmp_path / "cal.yaml")
    targets = os.path.join(root, "examples/mukca/panda_1_right.csv")
    cli("compensate", "--robot", tmp_path / "cal.yaml", "--nominal", urdf, "--tool-link",
        "ball_link", "--targets", targets, "--out", tmp_path / "c.csv")
    calibrated = lrcal.Robot.load(str(tmp_path / "cal.yaml"))
    nominal = lrcal.Robot.load(urdf, tool_link="ball_link")
    with open(targets) as f:
        q = np.array([[float(r[f"q{j + 1}"]) for j in range(7)] for r in csv.DictReader(f)])
    got = lrcal.compensate(calibrated, q, nominal=nominal)
    with open(tmp_path / "c.csv") as f:
        rows = list(csv.DictReader(f))
    program = np.array([[float(r[f"q{j + 1}"]) for j in range(7)] for r in rows])
    np.testing.assert_allclose(got["q"], program, rtol=0, atol=1e-12)
    assert all(got["converged"]) and all(got["within_limits"])
    # The calibrated model at the compensated commands is where the nominal plan meant to be.
    reached = lrcal.forward_kinematics(calibrated, got["q"])
    planned = lrcal.forward_kinematics(nominal, q)
    np.testing.assert_allclose(reached, planned, rtol=0, atol=1e-9)
    # Position targets alone: three rows of the task.
    pos = lrcal.compensate(calibrated, q, xyz=planned[:, :3, 3])
    assert np.all(pos["orientation_error_mrad"] == 0)
    assert np.max(pos["position_error_mm"]) < 1e-6
    with pytest.raises(lrcal.InputError, match="nominal: missing"):
        lrcal.compensate(calibrated, q)


def test_mixed_with_the_ranger_as_the_program(tmp_path, cli, paper):
    q = lrcal.sample_configurations(paper, 40, seed=3)
    configs = tmp_path / "c.csv"
    write_configurations(configs, q)
    cli("simulate", "--configs", configs, "--repetitions", "1", "--seed", "5",
        "--out", tmp_path / "r.csv")
    cli("simulate", "--sensor", "point", "--configs", configs, "--instrument", TRACKER_ARG,
        "--seed", "6", "--out", tmp_path / "p.csv")
    with open(tmp_path / "r.csv") as f:
        ranger = list(csv.DictReader(f))
    with open(tmp_path / "p.csv") as f:
        points = list(csv.DictReader(f))
    joints = [f"q{j + 1}" for j in range(6)]
    parts = [dict(sensor="ranger", q=np.array([[float(r[c]) for c in joints] for r in ranger]),
                  h=np.array([float(r["h"]) for r in ranger])),
             dict(sensor="point", q=np.array([[float(r[c]) for c in joints] for r in points]),
                  xyz=np.array([[float(r[c]) for c in "xyz"] for r in points]),
                  repetitions=[int(r["readings"]) for r in points], instrument=TRACKER)]
    fit = lrcal.identify_mixed(paper, parts, auto_fix=True, sigma_mm=0.2)
    done = cli("identify", "--sensor", "ranger,point", "--data", tmp_path / "r.csv", "--data",
               tmp_path / "p.csv", "--instrument", TRACKER_ARG, "--auto-fix", "--sigma-mm",
               "0.2", "--format", "json")
    program = json.loads(done.stdout)
    assert fit.names == [p["name"] for p in program["parameters"]]
    np.testing.assert_allclose(fit.delta, [p["delta"] for p in program["parameters"]],
                               rtol=0, atol=1e-12)
    assert "plane_f" not in fit.names  # the plane's terms only with estimate_plane
    with pytest.raises(lrcal.InputError, match=r"parts\[0\]\.h: expected one reading"):
        lrcal.identify_mixed(paper, [dict(parts[0], h=parts[0]["h"][:5])])
