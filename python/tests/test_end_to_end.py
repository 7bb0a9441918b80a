"""End to end from Python on short simulated flights: simulate → training data → train a small GP →
localize without and with the correction → metrics; plus the eval bindings' errors and round trips."""
import numpy as np
import pytest

import uwbtdoa as u
from conftest import pilot_flight, pilot_survey


@pytest.fixture(scope="module")
def flights():
    train = u.simulate_flight("zigzag", 50.0, seed=1)
    test = u.simulate_flight("circle", 35.0, seed=2, anchors=train["survey"])
    return train, test


@pytest.fixture(scope="module")
def trained(flights):
    train, _ = flights
    data = u.build_bias_dataset([train["flight"]], train["survey"])
    model, report = u.train_bias_model(data, "z1", 15, epochs=5, seed=1)
    return data, model, report


def test_training_data_match_the_simulated_error(flights, trained):
    train, _ = flights
    data, _, _ = trained
    a = data.arrays()
    assert len(data) == a["error"].size > 1000
    assert data.flights[0]["n_used"] == len(data)
    # ε of the dataset is the simulator's error of the same measurements (up to the 1 mm pose quantization)
    tdoa = train["flight"].tdoa
    idx = np.searchsorted(tdoa["t"], a["t"])
    np.testing.assert_allclose(a["error"], train["tdoa_truth"]["error"][idx], atol=0.01)
    X = u.feature_matrix("yaw_angles", a)
    assert X.shape == (len(data), 2)
    np.testing.assert_array_equal(X[:, 0], a["yaw_a"])


def test_bias_calibration_on_a_flight_the_model_was_not_trained_on(flights, trained):
    _, test = flights
    data, model, report = trained
    assert np.isfinite(report["final_elbo"])
    test_data = u.build_bias_dataset([test["flight"]], test["survey"])
    c = u.bias_calibration(test_data, model)
    # the counts add up, coverages are fractions that grow with the interval, the NLPD is a number
    assert c["n"] + c["n_uncovered"] == len(test_data)
    assert 0.0 <= c["coverage_1sigma"] <= c["coverage_2sigma"] <= 1.0
    assert len(c["levels"]) == len(c["coverage"])
    assert all(a <= b + 1e-12 for a, b in zip(c["coverage"], c["coverage"][1:]))
    assert np.isfinite(c["nlpd"]) and c["rmse_m"] > 0
    # scored with the model's predictive shape (docs/math/gp.md P43b), which the training report also scores on its
    # held-out time blocks
    assert (c["predictive_dof"], c["predictive_scale"]) == (3.0, 0.8)
    assert 0.0 <= report["holdout_coverage_1sigma"] <= report["holdout_coverage_2sigma"] <= 1.0
    assert report["mean_predictive_std_m"] > report["mean_predicted_std_m"] > 0
    assert np.isfinite(report["holdout_nlpd"])


def test_train_localize_and_compare(flights, trained, tmp_path):
    _, test = flights
    _, model, report = trained
    assert report["n_train"] > 0 and report["num_models"] == 1
    # WHEN the test flight is localized without and with the correction
    plain = u.localize_flight(test["flight"], test["survey"])
    corrected = u.localize_flight(test["flight"], test["survey"], bias_model=model)
    # THEN both give a full trajectory with per-axis position std and metrics against the ground truth
    for run in (plain, corrected):
        traj = run["trajectory"]
        assert traj["p"].shape[0] == traj["t"].size > 1000 and traj["sigma_p"].shape == traj["p"].shape
        assert np.all(traj["sigma_p"] > 0)
        # the IMU biases the filter estimated, per sample (body frame), finite with the IMU-driven filter
        assert traj["acc_bias"].shape == traj["gyro_bias"].shape == traj["p"].shape
        assert np.all(np.isfinite(traj["acc_bias"])) and np.all(np.isfinite(traj["gyro_bias"]))
        air = run["metrics"]["airborne"]
        assert 0 < air["rmse_m"] < 1.5 and air["n"] > 100
        s = run["metrics"]["samples"]
        np.testing.assert_allclose(np.sqrt(np.mean(s["error_norm"][s["airborne"]] ** 2)), air["rmse_m"], rtol=1e-9)
    # a flight logged from the ground does not start in motion; its take-off comes before its landing
    assert plain["summary"]["started_in_motion"] is False
    assert plain["summary"]["ready_t_s"] <= plain["summary"]["takeoff_t_s"] < plain["summary"]["landing_t_s"]
    # the ground periods: entered before the take-off, left at it, and the landing the last one entered
    entered, left = plain["summary"]["ground_entered_t_s"], plain["summary"]["ground_left_t_s"]
    assert entered[0] < plain["summary"]["takeoff_t_s"] == left[0] and entered[-1] == plain["summary"]["landing_t_s"]
    # the bias level measured in flight (filter.md F23c) is reported, and switched off with its memory
    assert plain["summary"]["n_bias_level_windows"] > 10 and 0 < plain["summary"]["bias_level_m"] < 1
    fixed = u.localize_flight(test["flight"], test["survey"], params={"output_bias_memory_s": 0.0})
    assert fixed["summary"]["n_bias_level_windows"] == 0 and np.isnan(fixed["summary"]["bias_level_m"])
    np.testing.assert_array_equal(fixed["trajectory"]["p"], plain["trajectory"]["p"])
    assert np.all(plain["trajectory"]["sigma_p"] >= fixed["trajectory"]["sigma_p"] - 1e-12)
    # with a model the level of the uncorrected TDoA is measured too (filter.md F24b); the mean is scaled only when
    # the model knows its training flights' level (trained on filter inputs) and this flight's is lower
    cs = corrected["summary"]
    assert 0 < cs["raw_bias_level_m"] < 1 and 0 < cs["min_bias_model_mean_scale"] <= cs["bias_model_mean_scale"] <= 1
    if model.training_bias_level_m == 0:
        assert cs["bias_model_mean_scale"] == 1.0
    # the level of the model's own mean (F24c): measured on this flight when the model knows it from its training
    if model.training_mean_level_m > 0:
        assert model.training_bias_level_m > 0 and 0 <= cs["model_mean_level_m"] < 1
    else:
        assert np.isnan(cs["model_mean_level_m"])
    # the correction changes the estimate
    assert not np.allclose(plain["trajectory"]["p"], corrected["trajectory"]["p"])
    # metrics recomputed from the arrays agree with the filter run's
    m = u.compute_trajectory_metrics(plain["trajectory"], test["flight"])
    assert m["airborne"]["rmse_m"] == pytest.approx(plain["metrics"]["airborne"]["rmse_m"], rel=1e-9)
    # the model file round trips and predicts the same
    path = tmp_path / "bias.json"
    model.save(str(path))
    back = u.BiasModel.load(str(path))
    feats = u.make_tdoa_features([0, 1], [1, 2], [[0, 0, 1.5]], [0, 0, 0, 1], test["survey"].position(0),
                                 test["survey"].position(1))
    np.testing.assert_allclose(back.predict(feats)["mean"], model.predict(feats)["mean"], rtol=1e-12)


def test_a_gp_trained_in_python_drives_the_filter(flights, trained):
    _, test = flights
    data, _, _ = trained
    a = data.arrays()
    X = u.feature_matrix("yaw_angles", a)
    gp = u.init_svgp(u.Kernel.preset("z1"), X, a["error"], 10)
    u.train_svgp(gp, X, a["error"], epochs=2)
    model = u.BiasModel(gp, "yaw_angles")
    np.testing.assert_allclose(model.predict(a)["mean"][:50], gp.predict(X[:50])["mean"], rtol=1e-9, atol=1e-12)
    run = u.localize_flight(test["flight"], test["survey"], bias_model=model, params={"tdoa_sigma_m": 0.3})
    assert run["metrics"]["airborne"]["n"] > 100
    # the ToF fields are accepted; a simulated flight has no ToF stream, so nothing is fused and nothing changes
    tof = u.localize_flight(test["flight"], test["survey"], bias_model=model,
                            params={"tdoa_sigma_m": 0.3, "fuse_tof": True, "tof_sigma_m": 0.05})
    assert tof["summary"]["n_tof"] == 0 and tof["summary"]["n_tof_used"] == 0
    np.testing.assert_array_equal(tof["trajectory"]["p"], run["trajectory"]["p"])
    # the correction's pose dependence (docs/math/gp.md P47): as variance the estimate moves a little, in the row more
    var = u.localize_flight(test["flight"], test["survey"], bias_model=model,
                            params={"tdoa_sigma_m": 0.3, "bias_model_pose": "variance"})
    row = u.localize_flight(test["flight"], test["survey"], bias_model=model,
                            params={"tdoa_sigma_m": 0.3, "bias_model_pose": "jacobian"})
    assert var["metrics"]["airborne"]["n"] == run["metrics"]["airborne"]["n"]
    assert not np.array_equal(row["trajectory"]["p"], run["trajectory"]["p"])
    assert abs(row["metrics"]["airborne"]["rmse_m"] - run["metrics"]["airborne"]["rmse_m"]) < 0.1
    with pytest.raises(ValueError, match="bias_model_pose must be one of none, variance, jacobian"):
        u.localize_flight(test["flight"], test["survey"], bias_model=model, params={"bias_model_pose": "both"})


def test_eval_errors_are_value_and_os_errors(flights, trained, tmp_path):
    _, test = flights
    data, _, _ = trained
    with pytest.raises(ValueError, match="unknown filter parameter 'tdoa_sigma'"):
        u.localize_flight(test["flight"], test["survey"], params={"tdoa_sigma": 0.3})
    with pytest.raises(ValueError, match="unknown filter preset"):
        u.localize_flight(test["flight"], test["survey"], preset="fast")
    # the flight-mode supervisor's parameters (mode_…, filter.md F29) are checked like the others, orderings included
    assert {"mode_tdoa_window_s", "start_max_speed_mps", "start_floor_height_sigma_m"} <= set(u.filter_param_names())
    with pytest.raises(ValueError, match="params: mode_tdoa_window_s must be > 0"):
        u.localize_flight(test["flight"], test["survey"], params={"mode_tdoa_window_s": 0.0})
    with pytest.raises(ValueError, match="air_max_height_m > air_min_height_m"):
        u.localize_flight(test["flight"], test["survey"], params={"mode_air_max_height_m": 0.2})
    with pytest.raises(ValueError):
        u.train_bias_model(data, "no-such-kernel", 10)
    with pytest.raises(OSError):
        u.BiasModel.load(str(tmp_path / "absent.json"))
    with pytest.raises(ValueError, match="unknown feature map"):
        u.feature_matrix("angles", data.arrays())
    # a key that the feature map reads must be there (no silent zeros)
    a = data.arrays()
    X = u.feature_matrix("body_positions_anchors", a)
    assert X.shape == (len(a["id_a"]), 12) and np.all(np.linalg.norm(X[:, 6:9], axis=1) > 0.5)
    del a["w_p_anchor_b"]
    with pytest.raises(ValueError, match="'w_p_anchor_b' is missing; the feature map 'body_positions_anchors'"):
        u.feature_matrix("body_positions_anchors", a)
    assert u.feature_matrix("yaw_angles", a).shape[1] == 2
    # eq. 9 inputs plus the body position (pair-tdoa-pos, P26b)
    W = u.feature_matrix("body_positions_world", a)
    np.testing.assert_array_equal(W[:, 6:9], a["w_p_b"])
    np.testing.assert_array_equal(W[:, :6], X[:, :6])


def test_run_evaluation_writes_the_report_and_renders_its_figures(flights, tmp_path):
    train, test = flights
    lines = []
    r = u.run_evaluation({"zigzag": train["flight"]}, {"circle": test["flight"]}, train["survey"], kernels=["z1"],
                         inducing=[8, 12], repeats=1, epochs=2, out=str(tmp_path), command="pytest", progress=lines.append)
    assert [row["inducing"] for row in r["rows"]] == [8, 12]
    assert {"kernel", "change_pct", "change_pct_min", "change_pct_max", "coverage_1sigma", "coverage_2sigma",
            "nlpd"} <= set(r["rows"][0])
    run = r["runs"][0]
    assert run["change_pct"] == pytest.approx(100 * (run["rmse_corrected_m"] / run["rmse_uncorrected_m"] - 1))
    assert 0.0 <= run["coverage_1sigma"] <= run["coverage_2sigma"] <= 1.0
    assert any("training data" in line for line in lines)
    for name in ("results.json", "REPORT.md", "figdata/errors.csv", "fig5_improvement.png",
                 "fig6_error_distribution.png", "trajectory_circle.png"):
        assert (tmp_path / name).is_file(), name
    assert "fig5_improvement.png" in (tmp_path / "REPORT.md").read_text()


def test_the_default_training_pipeline_corrects_a_real_flight_it_was_not_trained_on():
    """build_bias_dataset and train_bias_model with their defaults (GP inputs from the filter's estimate, the
    pair-tdoa-pos preset with M = 30: what `uwbtdoa train` writes, docs/math/gp.md P26c) on the sine flights
    0425-traj6…9; the model takes the circle flight 0425-traj2 below the uncorrected filter, as the CLI's does."""
    survey = u.read_anchor_survey(str(pilot_survey("0425")))
    train = [u.read_flight_csv(str(pilot_flight(f"0425-traj{i}"))) for i in (6, 7, 8, 9)]
    test = u.read_flight_csv(str(pilot_flight("0425-traj2")))
    model, report = u.train_bias_model(u.build_bias_dataset(train, survey), seed=1)
    assert model.preset == "pair-tdoa-pos" and len(model.entries) > 1
    # the dataset carried the training flights' bias level as the filter measured it (filter.md F24b)
    assert model.training_bias_level_m > 0.1
    before = u.localize_flight(test, survey)["metrics"]["airborne"]["rmse_m"]
    after = u.localize_flight(test, survey, bias_model=model)["metrics"]["airborne"]["rmse_m"]
    # (0.103 → 0.095 m; one model on one flight: the leave-one-out splits of docs/results.md measure the correction)
    assert after < 0.95 * before, (before, after)
    # a flight more biased than the training flights gets the excess of its level as predictive variance (gp.md
    # P43c); a less biased one, or one of unknown level, nothing
    level = model.training_bias_level_m
    assert model.level_excess_variance_m2(2 * level) == pytest.approx(3 * level ** 2)
    assert model.level_excess_variance_m2(0.5 * level) == 0.0
    assert model.level_excess_variance_m2(float("nan")) == 0.0
    # the calibration on the test flight takes its level from the dataset's filter run
    cal = u.bias_calibration(u.build_bias_dataset([test], survey), model)
    assert 0.5 < cal["coverage_1sigma"] < 0.9 and 0.85 < cal["coverage_2sigma"] <= 1.0, cal
