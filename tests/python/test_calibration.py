"""The calibration core from Python: numpy shapes and dtypes, and the same numbers, bit for bit,
as the lrcal program (sample, simulate, identify, identifiability, design)."""
import csv
import json
import pathlib

import numpy as np
import pytest

import lrcal


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], np.array([[float(v) for v in r] for r in rows[1:]])


def test_version_and_data_directory():
    assert lrcal.__version__ == "0.2.0"
    assert lrcal.data_directory().endswith("share/lrcal")


def test_robot_file_is_read_as_the_program_reads_it(paper):
    assert paper.name == "paper"
    assert paper.num_joints == 6
    assert paper.nominal_values.shape == (30,) and paper.nominal_values.dtype == np.float64
    assert paper.value_names[:5] == ["theta1", "alpha1", "a1", "d1", "beta1"]
    assert len(paper.parameter_names) == 25
    np.testing.assert_array_equal(paper.true_values, paper.nominal_values + paper.true_errors)
    assert paper.joint_limits.shape == (6, 2)
    assert np.isclose(np.linalg.norm(paper.plane.normal), 1.0, atol=1e-15)


def test_forward_kinematics_and_readings_shapes_and_geometry(paper):
    q = lrcal.sample_configurations(paper, 25, seed=3)
    assert q.shape == (25, 6) and q.dtype == np.float64
    T = lrcal.forward_kinematics(paper, q)
    assert T.shape == (25, 4, 4)
    np.testing.assert_allclose(T[:, :3, :3] @ T[:, :3, :3].transpose(0, 2, 1),
                               np.broadcast_to(np.eye(3), (25, 3, 3)), atol=1e-12)
    h = lrcal.laser_readings(paper, q)
    assert h.shape == (25,) and h.dtype == np.float64
    # Independent check: the point p + h·b lies on the plane n·x + f = 0.
    n, f = paper.plane.normal, paper.plane.offset
    hit = T[:, :3, 3] + h[:, None] * T[:, :3, 2]
    np.testing.assert_allclose(hit @ n + f, 0, atol=1e-12)
    # One configuration as a vector; the true model differs from the nominal one.
    assert lrcal.forward_kinematics(paper, q[0]).shape == (1, 4, 4)
    assert not np.array_equal(lrcal.forward_kinematics(paper, q, model="true"), T)
    np.testing.assert_array_equal(lrcal.forward_kinematics(paper, q, model=paper.nominal_values),
                                  T)


def test_missed_beams_are_nan_with_their_reason(paper):
    q = lrcal.sample_configurations(paper, 200, seed=5, validation=True)
    h, status = lrcal.laser_readings(paper, q, return_status=True)
    missed = np.isnan(h)
    assert missed.any() and not missed.all()
    assert [s != "ok" for s in status] == missed.tolist()


def test_sample_simulate_identify_match_the_program_bit_for_bit(tmp_path, cli, paper):
    configs, data = tmp_path / "c.csv", tmp_path / "m.csv"
    cli("sample", "--robot", "paper", "--count", 60, "--seed", 7, "--out", configs)
    cli("simulate", "--robot", "paper", "--configs", configs, "--seed", 7, "--out", data)
    program = json.loads(cli("identify", "--robot", "paper", "--data", data, "--sigma-mm", 0.2,
                             "--format", "json").stdout)

    q = lrcal.sample_configurations(paper, 60, seed=7)
    _, c = read_csv(configs)
    np.testing.assert_array_equal(q, c)
    readings = lrcal.simulate(paper, q, sigma_mm=0.2, repetitions=10, seed=7)
    header, m = read_csv(data)
    assert readings.q.shape == (600, 6) and readings.h.shape == (600,)
    np.testing.assert_array_equal(readings.q, m[:, :6])
    np.testing.assert_array_equal(readings.h, m[:, header.index("h")])
    np.testing.assert_array_equal(readings.configuration, np.repeat(np.arange(60), 10))

    result = lrcal.identify(paper, readings.q, readings.h, sigma_mm=0.2)
    assert result.termination == program["termination"] == "converged"
    assert result.names == [p["name"] for p in program["parameters"]]
    np.testing.assert_array_equal(result.estimate, [p["estimate"] for p in program["parameters"]])
    np.testing.assert_array_equal(result.std, [p["std"] for p in program["parameters"]])
    np.testing.assert_array_equal(result.covariance, program["covariance"])
    np.testing.assert_array_equal(result.covariance_given, program["covariance_given_sigma"])
    np.testing.assert_array_equal(result.correlation, program["correlation"])
    assert result.iterations == program["iterations"]
    assert result.sigma_hat == program["sigma_hat"]
    assert result.covariance.shape == (25, 25) and result.estimate.dtype == np.float64
    assert result.usable and "converged" in repr(result) and "theta1" in str(result)


def test_identify_names_suspects_by_configuration_label_as_the_program(tmp_path, cli, paper):
    q = lrcal.sample_configurations(paper, 60, seed=4)
    readings = lrcal.simulate(paper, q, sigma_mm=0.2, repetitions=10, seed=4)
    h = readings.h.copy()
    h[readings.configuration == 17] += 0.5e-3  # 8 sigma on the mean of 10
    labels = [f"station_{c + 1}" for c in readings.configuration]
    data = tmp_path / "m.csv"
    with open(data, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow([f"q{j + 1}" for j in range(6)] + ["h", "configuration"])
        for row, value, label in zip(readings.q, h, labels):
            w.writerow([repr(float(v)) for v in row] + [repr(float(value)), label])
    done = cli("identify", "--robot", "paper", "--data", data, "--sigma-mm", 0.2, "--format",
               "json", check=False)
    program = json.loads(done.stdout)["fit"]
    result = lrcal.identify(paper, readings.q, h, sigma_mm=0.2, configuration=labels)
    assert result.fit["suspects"] == [s - 1 for s in program["suspects"]]
    assert result.fit["suspect_labels"] == program["suspect_labels"] == ["station_18"]
    assert "suspect_labels" not in lrcal.identify(paper, readings.q, h, sigma_mm=0.2).fit
    with pytest.raises(lrcal.InputError, match="expected one label per reading"):
        lrcal.identify(paper, readings.q, h, configuration=labels[:-1])
    with pytest.raises(lrcal.InputError, match=r"configuration\[3\]: empty"):
        lrcal.identify(paper, readings.q, h, configuration=labels[:3] + [""] + labels[4:])


def test_identify_with_priors_matches_the_program_bit_for_bit(tmp_path, cli, paper):
    """lrcal.identify(prior_sigma=...) is `lrcal identify --prior-sigma`: the same maximum
    a-posteriori estimate, covariance and posterior/prior ratios, and the same refusals."""
    configs, data = tmp_path / "c.csv", tmp_path / "m.csv"
    priors = "theta=5mrad,alpha=5mrad,beta=5mrad,a=5mm,d6=0.2mm,d=5mm"
    cli("sample", "--robot", "paper", "--count", 40, "--seed", 3, "--out", configs)
    cli("simulate", "--robot", "paper", "--configs", configs, "--seed", 3, "--out", data)
    program = json.loads(cli("identify", "--robot", "paper", "--data", data, "--sigma-mm", 0.2,
                             "--prior-sigma", priors, "--format", "json").stdout)
    header, m = read_csv(data)
    result = lrcal.identify(paper, m[:, :6], m[:, header.index("h")], sigma_mm=0.2,
                            prior_sigma=priors)
    assert "with priors" in repr(result)
    np.testing.assert_array_equal(result.estimate, [p["estimate"] for p in program["parameters"]])
    np.testing.assert_array_equal(result.covariance_given, program["covariance_given_sigma"])
    np.testing.assert_array_equal(result.prior_sigma,
                                  [p["prior_sigma"] for p in program["parameters"]])
    np.testing.assert_array_equal(result.posterior_to_prior,
                                  [p["posterior_to_prior"] for p in program["parameters"]])
    assert result.prior_sigma[result.names.index("d6")] == 0.2e-3
    assert result.set_by_prior == program["set_by_prior"]
    # The robot file's tolerances: as priors (prior=True), the keyword's entries over them.
    robot = tmp_path / "tolerant.yaml"
    robot.write_text((pathlib.Path(__file__).parents[2] / "studies/robots/paper.yaml").read_text()
                     + "tolerances:\n  angle_unit: mrad\n  length_unit: mm\n"
                       "  every_link: {theta: 5, alpha: 5, beta: 5, a: 5, d: 5}\n")
    tolerant = lrcal.Robot.load(str(robot))
    from_file = lrcal.identify(tolerant, m[:, :6], m[:, header.index("h")], sigma_mm=0.2,
                               prior=True, prior_sigma="d6=0.2mm")
    np.testing.assert_array_equal(from_file.estimate, result.estimate)
    with pytest.raises(lrcal.InputError, match="prior=: the robot file"):
        lrcal.identify(paper, m[:, :6], m[:, header.index("h")], sigma_mm=0.2, prior=True)
    with pytest.raises(lrcal.InputError, match=r"prior_sigma=: 'd=1': 'd' is a length"):
        lrcal.identify(paper, m[:, :6], m[:, header.index("h")], sigma_mm=0.2, prior_sigma="d=1")
    with pytest.raises(lrcal.InputError, match="prior_sigma=: priors are weighed"):
        lrcal.identify(paper, m[:, :6], m[:, header.index("h")], prior_sigma="d=1mm")


def test_identify_with_a_median_of_the_readings_matches_the_program(tmp_path, cli, paper):
    """lrcal.identify(average="median") is `lrcal identify --average median`, bit for bit: gross
    errors that reject the means' fit leave the medians' consistent."""
    configs, data = tmp_path / "c.csv", tmp_path / "m.csv"
    cli("sample", "--robot", "paper", "--count", 60, "--seed", 4, "--out", configs)
    cli("simulate", "--robot", "paper", "--configs", configs, "--seed", 5, "--repetitions", 5,
        "--sigma-mm", 0.05, "--outlier-fraction", 0.05, "--out", data)
    program = json.loads(cli("identify", "--robot", "paper", "--data", data, "--sigma-mm", 0.05,
                             "--average", "median", "--format", "json").stdout)
    header, m = read_csv(data)
    q, h = m[:, :6], m[:, header.index("h")]
    result = lrcal.identify(paper, q, h, sigma_mm=0.05, average="median")
    np.testing.assert_array_equal(result.estimate, [p["estimate"] for p in program["parameters"]])
    np.testing.assert_array_equal(result.covariance_given, program["covariance_given_sigma"])
    assert program["fit"]["consistent"]
    assert not lrcal.identify(paper, q, h, sigma_mm=0.05).fit["consistent"]
    with pytest.raises(lrcal.InputError, match="average=: expected mean, median or trimmed:F"):
        lrcal.identify(paper, q, h, sigma_mm=0.05, average="mode")


def test_identify_with_errors_in_variables_matches_the_program(tmp_path, cli, paper):
    """lrcal.identify(encoder_sigma_mrad=...) is `lrcal identify --encoder-sigma-mrad`, bit for
    bit, and needs sigma_mm as the program does."""
    configs, data = tmp_path / "c.csv", tmp_path / "m.csv"
    cli("sample", "--robot", "paper", "--count", 40, "--seed", 4, "--out", configs)
    cli("simulate", "--robot", "paper", "--configs", configs, "--seed", 5, "--repetitions", 1,
        "--sigma-mm", 0.05, "--encoder-sigma-mrad", 0.1, "--out", data)
    program = json.loads(cli("identify", "--robot", "paper", "--data", data, "--sigma-mm", 0.05,
                             "--encoder-sigma-mrad", 0.1, "--format", "json").stdout)
    header, m = read_csv(data)
    result = lrcal.identify(paper, m[:, :6], m[:, header.index("h")], sigma_mm=0.05,
                            encoder_sigma_mrad=0.1)
    assert "errors in variables" in repr(result)
    np.testing.assert_array_equal(result.estimate, [p["estimate"] for p in program["parameters"]])
    np.testing.assert_array_equal(result.covariance_given, program["covariance_given_sigma"])
    with pytest.raises(lrcal.InputError, match="encoder_sigma_mrad"):
        lrcal.identify(paper, m[:, :6], m[:, header.index("h")], encoder_sigma_mrad=0.1)


def test_prior_information_matches_identifiability_with_priors(tmp_path, cli, paper):
    """lrcal.prior_information is `lrcal identifiability --prior-sigma`'s table, bit for bit."""
    configs = tmp_path / "c.csv"
    priors = "theta=5mrad,alpha=5mrad,beta=5mrad,a=5mm,d=5mm"
    plane = "0,0,1,0.3"
    cli("sample", "--robot", "paper", "--count", 60, "--plane", plane, "--out", configs)
    program = json.loads(cli("identifiability", "--robot", "paper", "--configs", configs,
                             "--plane", plane, "--prior-sigma", priors, "--sigma-mm", 0.2,
                             "--repetitions", 10, "--format", "json").stdout)["priors"]
    _, q = read_csv(configs)
    info = lrcal.prior_information(paper, q[:, :6], prior_sigma=priors, sigma_mm=0.2,
                                   repetitions=10, plane=(0, 0, 1, 0.3))
    assert info.defined and info.set_by_prior == program["set_by_prior"] == ["theta1", "a1", "d3"]
    np.testing.assert_array_equal(info.posterior_sigma,
                                  [t["posterior_sigma"] for t in program["terms"]])
    assert "set by the prior" in str(info)
    with pytest.raises(lrcal.InputError, match="sigma_mm="):
        lrcal.prior_information(paper, q[:, :6], prior_sigma=priors, sigma_mm=0,
                                plane=(0, 0, 1, 0.3))
    with pytest.raises(lrcal.InputError, match="give priors"):
        lrcal.prior_information(paper, q[:, :6])


def test_identification_recovers_the_true_errors_without_noise(paper):
    q = lrcal.sample_configurations(paper, 60, seed=11)
    h = lrcal.laser_readings(paper, q, model="true")
    hit = ~np.isnan(h)  # the true arm's beam may miss where the nominal one hits
    result = lrcal.identify(paper, q[hit], h[hit])
    truth = np.array([paper.true_errors[paper.value_names.index(n)] for n in result.names])
    np.testing.assert_allclose(result.delta, truth, atol=1e-10)


def test_identifiability_and_design_match_the_program(tmp_path, cli, paper):
    pool = tmp_path / "pool.csv"
    cli("sample", "--robot", "paper", "--count", 101, "--seed", 2, "--out", pool)
    _, q = read_csv(pool)
    program = json.loads(cli("identifiability", "--robot", "paper", "--configs", pool,
                             "--format", "json").stdout)
    report = lrcal.identifiability(paper, q)
    assert report.rank == program["rank"] == 25 and report.full_rank
    np.testing.assert_array_equal(report.singular_values, program["singular_values"])
    few = lrcal.identifiability(paper, q[:10])
    assert not few.full_rank and few.suggested_fixed and few.dependencies

    program = json.loads(cli("design", "--robot", "paper", "--pool", pool, "--select", 40,
                             "--baseline", 1, "--format", "json").stdout)
    design = lrcal.design(paper, q, 40)
    assert design.indices == program["selected"]
    assert design.score == program["score"]
    assert design.criterion == "E" and design.method == "exchange"


def test_design_with_every_criterion_is_the_programs_design(tmp_path, cli, paper):
    """The same library call (design/design_choice.h): selection, criterion I's prediction, the
    random baseline and the certificate are the program's, bit for bit."""
    pool = tmp_path / "pool.csv"
    cli("sample", "--robot", "paper", "--count", 70, "--seed", 5, "--out", pool)
    _, q = read_csv(pool)
    for criterion in ("D", "I"):
        program = json.loads(cli("design", "--robot", "paper", "--pool", pool, "--select", 30,
                                 "--criterion", criterion, "--workspace", 25, "--baseline", 50,
                                 "--method", "backward", "--format", "json").stdout)
        design = lrcal.design(paper, q, 30, criterion=criterion, workspace=25, baseline=50,
                              method="backward")
        mine = json.loads(design.json)
        for key in ("selected", "score", "criterion", "indices", "certificate", "task",
                    "selected_per_plane", "evaluations"):
            assert mine.get(key) == program.get(key), key
        assert design.indices == program["selected"]
        assert design.certificate == program["certificate"]["statement"]
        assert [b["criterion"] for b in design.baseline] == list(program["indices"])
    assert design.task_rms_per_sigma == program["task"]["rms_position_per_unit_sigma"]
    with pytest.raises(lrcal.InputError, match="expected_length_mm="):
        lrcal.design(paper, q, 30, expected_length_mm=0)
    with pytest.raises(lrcal.InputError, match="baseline="):
        lrcal.design(paper, q, 30, baseline=0)


def test_plan_accuracy_is_the_programs_plan(tmp_path):
    study = tmp_path / "setup.yaml"
    study.write_text("name: setup\nseed: 4\ntrials: 10\nrobot: paper\n"
                     "pool: {size: 50}\nvalidation: {size: 8}\n")
    plan = lrcal.plan_accuracy(str(study), "rms_pos=0.1mm", configurations="30:50:10",
                               trials=100, out_dir=str(tmp_path / "plan"), threads=2,
                               plan_on="data")
    assert plan["target"] == {"metric": "rms_pos", "value": 0.1, "unit": "mm",
                              "confidence": 0.95}
    assert plan["plan_on"] == "data" and "plane_f" in plan["defaulted"]
    chosen = plan["campaigns"][0]
    assert chosen["label"] == "chosen" and chosen["predicted"] <= 0.1
    assert chosen["predicted"] == chosen["predicted_data"] < chosen["predicted_total"]
    assert chosen["trials"] == 100 and pathlib.Path(plan["study"]).is_file()
    # On the total (the default) the paper's plane and ranger, taken as known with lrcal's
    # default tolerances, put 0.1 mm out of reach, and the message says what would help.
    with pytest.raises(lrcal.InputError, match="plan_on='data'"):
        lrcal.plan_accuracy(str(study), "rms_pos=0.1mm", configurations="30:50:10",
                            out_dir=str(tmp_path / "total"))
    with pytest.raises(lrcal.InputError, match="plan_on=: expected total or data"):
        lrcal.plan_accuracy(str(study), "rms_pos=0.1mm", plan_on="noise")
    with pytest.raises(lrcal.InputError, match="target=: the value needs its unit"):
        lrcal.plan_accuracy(str(study), "rms_pos=0.1")
    with pytest.raises(lrcal.InputError, match="confidence="):
        lrcal.plan_accuracy(str(study), "rms_pos=0.1mm", confidence=1.5)


def test_design_indices_are_rows_of_the_pool_given(paper):
    anywhere = lrcal.sample_configurations(paper, 150, seed=9, validation=True)
    design = lrcal.design(paper, anywhere, 30, method="greedy")
    rejected = {row for row, _ in design.rejected}
    assert rejected and not rejected & set(design.indices)
    h = lrcal.laser_readings(paper, anywhere[design.indices])
    assert not np.isnan(h).any()
    # The settings' ranges are the library's (DesignRequest::Settings), in Python's words.
    with pytest.raises(lrcal.InputError, match=r"^baseline=: expected 1 to 1,000,000"):
        lrcal.design(paper, anywhere, 30, baseline=0)
    with pytest.raises(lrcal.InputError, match=r"^expected_angle_mrad=: expected a finite value > 0"):
        lrcal.design(paper, anywhere, 30, scaling="expected", expected_angle_mrad=0)


def test_docstrings_say_what_the_arguments_are():
    for function in (lrcal.identify, lrcal.simulate, lrcal.design, lrcal.identifiability,
                     lrcal.forward_kinematics, lrcal.laser_readings, lrcal.run_study,
                     lrcal.load_run, lrcal.sample_configurations, lrcal.plan_accuracy):
        assert function.__doc__ and len(function.__doc__) > 200, function.__name__
    doc = lrcal.identify.__doc__
    for words in ("identify(robot", "estimate_plane", "(M, joints) rad", "lrcal.InputError"):
        assert words in doc


def test_urdf_robot_loads_with_its_tool_link_as_the_program_does(tmp_path, cli):
    urdf = str(pathlib.Path(__file__).resolve().parents[2] / "examples/urdf/ur5_ranger.urdf")
    with pytest.raises(lrcal.InputError, match="--tool-link"):
        lrcal.Robot.load(urdf)  # two end links: the ranger's must be named
    arm = lrcal.Robot.load(urdf, tool_link="ranger")
    assert arm.num_joints == 6 and arm.name == "ur5_ranger"
    q = lrcal.sample_configurations(arm, 5, seed=2, plane=(0, 0, 1, 0), validation=True)
    T = lrcal.forward_kinematics(arm, q)
    configs = tmp_path / "q.csv"
    configs.write_text("q1,q2,q3,q4,q5,q6\n" +
                       "\n".join(",".join(repr(v) for v in row) for row in q) + "\n")
    poses = json.loads(cli("kinematics", "--robot", urdf, "--tool-link", "ranger", "--plane",
                           "0,0,1,0", "--configs", configs, "--format", "json").stdout)
    # The module composes 4x4 matrices, the program its trig-free chain: rounding apart.
    np.testing.assert_allclose(T[:, :3, 3], np.array([p["position"] for p in poses]), atol=1e-12)


def test_settings_have_the_command_lines_names_units_and_checks(tmp_path, cli, paper):
    """The noise and identification settings come from one schema: the same names (sigma_mm,
    encoder_sigma_mrad, loss_scale_mm...), units and ranges as lrcal simulate/identify."""
    q = lrcal.sample_configurations(paper, 30, seed=3)
    configs, data = tmp_path / "c.csv", tmp_path / "m.csv"
    np.savetxt(configs, q, delimiter=",", header="q1,q2,q3,q4,q5,q6", comments="", fmt="%.17g")
    disturbed = dict(sigma_mm=0.1, repetitions=4, encoder_sigma_mrad=0.05, form_sigma_mm=0.02,
                     outlier_fraction=0.1, outlier_sigma_mm=2.0)
    args = [a for k, v in disturbed.items() for a in ("--" + k.replace("_", "-"), v)]
    cli("simulate", "--robot", "paper", "--configs", configs, "--seed", 5, "--out", data, *args)
    readings = lrcal.simulate(paper, q, seed=5, **disturbed)
    header, m = read_csv(data)
    np.testing.assert_array_equal(readings.h, m[:, header.index("h")])

    # The earlier spellings (metres) give the same numbers; both at once is refused.
    earlier = lrcal.simulate(paper, q, sigma=0.1e-3, repetitions=4, seed=5)
    np.testing.assert_array_equal(earlier.h, lrcal.simulate(paper, q, sigma_mm=0.1,
                                                            repetitions=4, seed=5).h)
    with pytest.raises(lrcal.InputError, match="not both"):
        lrcal.simulate(paper, q, sigma_mm=0.3, sigma=0.1e-3)
    a = lrcal.identify(paper, readings.q, readings.h, loss="huber", loss_scale_mm=0.3,
                       sigma_mm=0.1)
    b = lrcal.identify(paper, readings.q, readings.h, loss="huber", loss_scale=0.3e-3,
                       sigma=0.1e-3)
    np.testing.assert_array_equal(a.estimate, b.estimate)
    # The scale in multiples of sigma_mm (as --loss-scale-sigma and a study's
    # identification.loss_scale_sigma): the same fit as the product in mm (3 × 0.1e-3 m and
    # 0.3e-3 m differ in the last bit, hence the tolerance).
    c = lrcal.identify(paper, readings.q, readings.h, loss="huber", loss_scale_sigma=3.0,
                       sigma_mm=0.1)
    np.testing.assert_allclose(c.estimate, a.estimate, rtol=1e-9, atol=1e-14)
    assert "(3 σ)" in c.loss
    with pytest.raises(lrcal.InputError, match=r"^loss_scale_sigma=: .*not both"):
        lrcal.identify(paper, readings.q, readings.h, loss="huber", loss_scale_sigma=3.0,
                       loss_scale_mm=0.3, sigma_mm=0.1)
    with pytest.raises(lrcal.InputError,
                       match=r"^loss_scale_sigma=: a loss scale in multiples of sigma needs"):
        lrcal.identify(paper, readings.q, readings.h, loss="huber", loss_scale_sigma=3.0)

    # Out of range: the command line's message in Python's words.
    with pytest.raises(lrcal.InputError, match=r"^sigma_mm=: expected a finite value >= 0 \(mm\)"):
        lrcal.simulate(paper, q, sigma_mm=-1)
    with pytest.raises(lrcal.InputError, match=r"repetitions=: expected 1 to 1,000,000 readings"):
        lrcal.simulate(paper, q, repetitions=0)
    with pytest.raises(lrcal.InputError, match=r"outlier_fraction=: expected a value in \[0, 1\]"):
        lrcal.simulate(paper, q, outlier_fraction=1.5)
    with pytest.raises(lrcal.InputError, match=r"loss_scale_mm=: expected a finite value > 0"):
        lrcal.identify(paper, readings.q, readings.h, loss="huber", loss_scale_mm=0)
    with pytest.raises(lrcal.InputError, match=r"^loss_scale_sigma=: expected a finite value >= 0"):
        lrcal.identify(paper, readings.q, readings.h, loss="huber", loss_scale_sigma=-1,
                       sigma_mm=0.1)
    with pytest.raises(lrcal.InputError, match=r"max_iterations=: expected 1 to 10,000"):
        lrcal.identify(paper, readings.q, readings.h, max_iterations=0)
    # Sampling, selection and identifiability settings: the same schema, Python's names.
    with pytest.raises(lrcal.InputError,
                       match=r"^min_singular_value=: expected a finite value >= 0, got -1"):
        lrcal.sample(paper, 5, min_singular_value=-1)
    with pytest.raises(lrcal.InputError,
                       match=r"^samples=: expected 1 to 1,000,000 random subsets, got 0"):
        lrcal.design(paper, q, 26, method="sampled", samples=0)
    with pytest.raises(lrcal.InputError, match=r"^restarts=: expected 1 to 1000 starts, got 0"):
        lrcal.design(paper, q, 26, restarts=0)
    with pytest.raises(lrcal.InputError, match=r"^rank_tolerance=: expected a value in \[0, 1\)"):
        lrcal.identifiability(paper, q, rank_tolerance=1)
    with pytest.raises(lrcal.InputError, match=r"threads=: expected 0 \(all cores\) to 4096"):
        lrcal.run_study("quick", str(tmp_path / "run"), threads=-1)


def test_identify_with_several_planes_ranger_holdout_and_predict_at_is_the_programs(tmp_path, cli,
                                                                                   paper):
    # Three planes (the README's), the ranger's offset estimated, 5-fold cross-validation and the
    # accuracy statement at poses: the numbers of `lrcal identify ... --format json`, bit for bit.
    planes_args = ["--plane", "0,0,1,0.3", "--plane", "1,0,0,0.9", "--plane", "0,1,0,0.9"]
    configs, data, poses = tmp_path / "c.csv", tmp_path / "m.csv", tmp_path / "p.csv"
    cli("sample", *planes_args, "--count", 40, "--seed", 5, "--out", configs)
    cli("simulate", *planes_args, "--configs", configs, "--seed", 5, "--out", data)
    cli("sample", "--count", 7, "--seed", 9, "--validation", "--out", poses)
    program = json.loads(cli("identify", *planes_args, "--data", data, "--sigma-mm", 0.2,
                             "--estimate-ranger", "offset", "--fix", "d6", "--holdout", 5,
                             "--predict-at", poses, "--format", "json").stdout)
    header, m = read_csv(data)
    planes = [lrcal.Plane((0, 0, 1), 0.3), lrcal.Plane((1, 0, 0), 0.9),
              lrcal.Plane((0, 1, 0), 0.9)]
    _, p = read_csv(poses)
    result = lrcal.identify(paper, m[:, :6], m[:, header.index("h")], plane=planes,
                            plane_of=m[:, header.index("plane")], sigma_mm=0.2,
                            estimate_ranger="offset", fix="d6", holdout=5, predict_at=p)
    assert result.names == [q["name"] for q in program["parameters"]]
    assert "ranger_offset" in result.names and "d6" not in result.names
    np.testing.assert_array_equal(result.estimate,
                                  [q["estimate"] for q in program["parameters"]])
    assert result.holdout == program["holdout"]
    assert result.accuracy == program["accuracy"]
    assert lrcal.identify(paper, m[:, :6], m[:, header.index("h")], plane=planes,
                          plane_of=m[:, header.index("plane")]).holdout is None
    with pytest.raises(lrcal.InputError, match="plane_of: 3 planes: give the plane each"):
        lrcal.identify(paper, m[:, :6], m[:, header.index("h")], plane=planes)
    with pytest.raises(lrcal.InputError, match=r"plane_of\[0\]: expected a plane number from 1 "
                                               "to 3, got 4"):
        lrcal.identify(paper, m[:, :6], m[:, header.index("h")], plane=planes,
                       plane_of=np.full(len(m), 4))
    with pytest.raises(lrcal.InputError, match="holdout=: expected 2 to 120 folds"):
        lrcal.identify(paper, m[:, :6], m[:, header.index("h")], plane=planes,
                       plane_of=m[:, header.index("plane")], holdout=121)
    with pytest.raises(lrcal.InputError, match="outside the joint's range"):
        lrcal.identify(paper, np.degrees(m[:, :6]), m[:, header.index("h")], plane=planes,
                       plane_of=m[:, header.index("plane")])
    q, h = m[:, :6], m[:, header.index("h")]
    tags = m[:, header.index("plane")]
    with pytest.raises(lrcal.InputError, match=r"predict_at: expected an array of shape \(N, 6\)"):
        lrcal.identify(paper, q, h, plane=planes, plane_of=tags, predict_at=np.zeros((3, 5)))
    with pytest.raises(lrcal.InputError, match="estimate_ranger: unknown ranger term 'offst'"):
        lrcal.identify(paper, q, h, plane=planes, plane_of=tags, estimate_ranger="offst")
    with pytest.raises(lrcal.InputError, match=r"plane_of: expected one plane number \(from 1\)"):
        lrcal.identify(paper, q, h, plane=planes, plane_of=["a"] * len(q))
    with pytest.raises(lrcal.InputError, match=r"plane_of: expected one plane number per reading "
                                               r"\(1200\), got 3"):
        lrcal.identify(paper, q, h, plane=planes, plane_of=[1, 2, 3])


def test_identifiability_with_several_planes_and_ranger_terms_is_the_programs(tmp_path, cli,
                                                                              paper):
    # With their offsets estimated, three planes still lose the ranger's offset against the tool
    # length d6, the first plane's offset against d1 and, with the scale, the scale against the
    # lengths and the other offsets: the same analysis as `lrcal identifiability`.
    planes_args = ["--plane", "0,0,1,0.3", "--plane", "1,0,0,0.9", "--plane", "0,1,0,0.9"]
    configs = tmp_path / "c.csv"
    cli("sample", *planes_args, "--count", 30, "--seed", 6, "--out", configs)
    header, c = read_csv(configs)
    planes = [lrcal.Plane((0, 0, 1), 0.3), lrcal.Plane((1, 0, 0), 0.9),
              lrcal.Plane((0, 1, 0), 0.9)]
    for ranger in ("offset", "offset,scale"):
        program = json.loads(cli("identifiability", *planes_args, "--configs", configs,
                                 "--estimate-ranger", ranger, "--estimate-plane", "offset",
                                 "--format", "json").stdout)
        mine = lrcal.identifiability(paper, c[:, :6], plane=planes,
                                     plane_of=c[:, header.index("plane")],
                                     estimate_plane="offset", estimate_ranger=ranger)
        assert mine.names == program["parameters"] and "ranger_offset" in mine.names
        assert mine.rank == program["rank"]
        np.testing.assert_array_equal(mine.singular_values, program["singular_values"])
        assert mine.suggested_fixed == program["suggested_fixed"]
        assert {"ranger_offset", "plane1_f"} <= set(mine.suggested_fixed)
    with pytest.raises(lrcal.InputError, match="plane_of: 3 planes"):
        lrcal.identifiability(paper, c[:, :6], plane=planes)


def test_identify_and_identifiability_with_base_and_tool_terms_are_the_programs(tmp_path, cli,
                                                                             paper):
    # The base's and the tool's terms asked for, the rank-deficient ones fixed (--auto-fix): the
    # same estimate and the same analysis as the program's, and the names it gives them.
    planes_args = ["--plane", "0,0,1,0.3", "--plane", "1,0,0,0.9", "--plane", "0,1,0,0.9"]
    configs, data = tmp_path / "c.csv", tmp_path / "m.csv"
    cli("sample", *planes_args, "--count", 30, "--seed", 7, "--out", configs)
    cli("simulate", *planes_args, "--configs", configs, "--seed", 7, "--out", data)
    program = json.loads(cli("identify", *planes_args, "--data", data, "--sigma-mm", 0.2,
                             "--estimate-base", "rpy", "--estimate-tool", "x,z,roll",
                             "--auto-fix", "--format", "json").stdout)
    header, m = read_csv(data)
    planes = [lrcal.Plane((0, 0, 1), 0.3), lrcal.Plane((1, 0, 0), 0.9),
              lrcal.Plane((0, 1, 0), 0.9)]
    q, h, tags = m[:, :6], m[:, header.index("h")], m[:, header.index("plane")]
    result = lrcal.identify(paper, q, h, plane=planes, plane_of=tags, sigma_mm=0.2,
                            estimate_base="rpy", estimate_tool="x,z,roll", auto_fix=True)
    assert result.names == [p["name"] for p in program["parameters"]]
    assert {"base_roll", "base_pitch"} <= set(result.names)
    np.testing.assert_array_equal(result.estimate, [p["estimate"] for p in program["parameters"]])
    mine = lrcal.identifiability(paper, q, plane=planes, plane_of=tags, estimate_base="rpy",
                                 estimate_tool="x,z,roll")
    analysis = json.loads(cli("identifiability", *planes_args, "--configs", configs,
                              "--estimate-base", "rpy", "--estimate-tool", "x,z,roll",
                              "--format", "json").stdout)
    assert mine.names == analysis["parameters"] and mine.names[-6:] == [
        "base_roll", "base_pitch", "base_yaw", "tool_x", "tool_z", "tool_roll"]
    assert mine.suggested_fixed == analysis["suggested_fixed"]
    assert "base_yaw" in mine.suggested_fixed or "theta1" in mine.suggested_fixed
    with pytest.raises(lrcal.InputError, match="estimate_tool: unknown frame term 'twist'"):
        lrcal.identify(paper, q, h, plane=planes, plane_of=tags, estimate_tool="x,twist")


def test_sample_simulate_readings_and_design_with_several_planes_are_the_programs(tmp_path, cli):
    # A robot file with two planes and true ranger errors (examples/rigs): sample, simulate and
    # design give the numbers of the commands, bit for bit; laser_readings reads each
    # configuration on its own plane.
    rig_path = pathlib.Path(__file__).parents[2] / "examples" / "rigs" / "seven_joint_ranger.yaml"
    rig = lrcal.Robot.load(str(rig_path))
    configs, data, chosen = tmp_path / "c.csv", tmp_path / "m.csv", tmp_path / "chosen.csv"
    cli("sample", "--robot", rig_path, "--count", 25, "--seed", 3, "--out", configs)
    cli("simulate", "--robot", rig_path, "--configs", configs, "--sigma-mm", 0.1,
        "--repetitions", 3, "--seed", 4, "--out", data)
    header, c = read_csv(configs)
    q, plane_of = lrcal.sample(rig, 25, seed=3, return_planes=True)
    np.testing.assert_array_equal(q, c[:, :7])
    np.testing.assert_array_equal(plane_of, c[:, header.index("plane")])
    assert sorted(set(plane_of)) == [1, 2] and plane_of.dtype.kind == "i"
    one, ones = lrcal.sample(rig, 5, seed=3, plane=rig.planes[0], return_planes=True)
    np.testing.assert_array_equal(one, lrcal.sample(rig, 5, seed=3, plane=rig.planes[0]))
    np.testing.assert_array_equal(ones, np.ones(5, dtype=int))
    with pytest.raises(lrcal.InputError, match=r"^return_planes: 2 planes: .*return_planes=True"):
        lrcal.sample(rig, 25, seed=3)

    readings = lrcal.simulate(rig, q, sigma_mm=0.1, repetitions=3, seed=4, plane_of=plane_of)
    mheader, m = read_csv(data)
    np.testing.assert_array_equal(readings.h, m[:, mheader.index("h")])
    np.testing.assert_array_equal(readings.plane_of, m[:, mheader.index("plane")])
    with pytest.raises(lrcal.InputError, match=r"^plane_of: 2 planes: give the plane each"):
        lrcal.simulate(rig, q, seed=4)

    # Each configuration read on its own plane: the one-plane call on that plane.
    h = lrcal.laser_readings(rig, q, plane_of=plane_of)
    planes = rig.planes
    for k, plane in enumerate(planes, start=1):
        mine = plane_of == k
        np.testing.assert_array_equal(h[mine], lrcal.laser_readings(rig, q[mine], plane=plane))

    program = json.loads(cli("design", "--robot", rig_path, "--pool", configs, "--select", 30,
                             "--method", "greedy", "--format", "json", "--out", chosen).stdout)
    design = lrcal.design(rig, q, 30, method="greedy", plane_of=plane_of)
    mine = json.loads(design.json)
    assert mine["score"] == program["score"]
    assert mine["selected_per_plane"] == program["selected_per_plane"]
    _, rows = read_csv(chosen)
    np.testing.assert_array_equal(q[design.indices], rows[:, :7])
    np.testing.assert_array_equal(plane_of[design.indices], rows[:, 7])


def _without_date(text):
    return "\n".join(line for line in text.splitlines()
                     if not line.lstrip().startswith(("date:", "lrcal:")))


def test_identify_writes_the_calibrated_robot_and_report_as_the_program_does(tmp_path, cli,
                                                                             paper):
    # identify(write_robot=, report=, data_file=) writes what --write-robot and --report write:
    # the same calibrated robot file (but for its date), the same calibration.json and a page.
    configs, data = tmp_path / "c.csv", tmp_path / "m.csv"
    cli("sample", "--count", 40, "--seed", 5, "--out", configs)
    cli("simulate", "--configs", configs, "--sigma-mm", 0.2, "--seed", 5, "--out", data)
    cli("identify", "--data", data, "--sigma-mm", 0.2, "--write-robot", tmp_path / "cli.yaml",
        "--report", tmp_path / "cli-report")
    header, m = read_csv(data)
    result = lrcal.identify(paper, m[:, :6], m[:, header.index("h")], sigma_mm=0.2,
                            write_robot=tmp_path / "py.yaml", report=tmp_path / "py-report",
                            data_file=data)
    assert _without_date((tmp_path / "py.yaml").read_text()) == \
        _without_date((tmp_path / "cli.yaml").read_text())
    for name in ("calibration.json", "calibrated.urdf"):
        assert (tmp_path / "py-report" / name).read_text() == \
            (tmp_path / "cli-report" / name).read_text()
    assert result.report == str(tmp_path / "py-report" / "report.html")
    assert "Calibration report" in (tmp_path / "py-report" / "report.html").read_text()
    calibrated = lrcal.Robot.load(str(tmp_path / "py.yaml"))
    np.testing.assert_array_equal(calibrated.nominal_values, lrcal.Robot.load(
        str(tmp_path / "cli.yaml")).nominal_values)

    # Without data_file the record names and hashes the arrays; a bad place is refused first.
    lrcal.identify(paper, m[:, :6], m[:, header.index("h")], write_robot=tmp_path / "arrays.yaml")
    assert f'data: "Python arrays: {len(m)} readings' in (tmp_path / "arrays.yaml").read_text()
    with pytest.raises(lrcal.InputError, match=r"^write_robot="):
        lrcal.identify(paper, m[:, :6], m[:, header.index("h")],
                       write_robot=tmp_path / "no" / "such" / "folder" / "x.yaml")
