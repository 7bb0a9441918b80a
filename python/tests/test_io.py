"""uwbtdoa io bindings: numpy round trips of flights and surveys, and errors as ValueError/OSError."""
import numpy as np
import pytest

import uwbtdoa as u
from conftest import pilot_flight, pilot_survey


def _synthetic_flight(rng, n_tdoa=50, n_imu=200, n_pose=60):
    id_a = rng.integers(0, 8, n_tdoa)  # and id_b another anchor: a TDoA needs two
    t_imu = np.sort(rng.uniform(0, 2, n_imu))
    q = rng.normal(size=(n_pose, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    return u.Flight(
        tdoa={"t": np.sort(rng.uniform(0, 2, n_tdoa)), "id_a": id_a,
              "id_b": (id_a + rng.integers(1, 8, n_tdoa)) % 8, "tdoa": rng.normal(0, 2, n_tdoa)},
        acc={"t": t_imu, "value": rng.normal(0, 9.81, (n_imu, 3))},
        gyro={"t": t_imu, "value": rng.normal(0, 1.0, (n_imu, 3))},
        pose={"t": np.sort(rng.uniform(0, 2, n_pose)), "p": rng.normal(0, 2, (n_pose, 3)), "q": q})


def test_flight_streams_are_numpy_arrays_in_si_units():
    # GIVEN a flight built from numpy arrays
    f = _synthetic_flight(np.random.default_rng(1))
    # THEN every stream comes back as arrays with the documented shapes and dtypes
    assert sorted(f.present) == ["acc", "gyro", "pose", "tdoa"]
    assert f.tdoa["id_a"].dtype == np.int32 and f.tdoa["tdoa"].dtype == np.float64
    assert f.acc["value"].shape == (200, 3)
    assert f.pose["q"].shape == (60, 4)
    assert set(f.streams()) == {"tdoa", "acc", "gyro", "pose"}


def test_a_window_keeps_every_stream_between_its_stamps():
    # GIVEN a flight whose streams span 0 … 2 s
    f = _synthetic_flight(np.random.default_rng(3))
    # WHEN it is cut to 0.5 … 1.5 s
    w = f.window(0.5, 1.5)
    # THEN each stream holds exactly its samples inside the window, stamps unchanged
    for name in ("tdoa", "acc", "gyro", "pose"):
        t = f.streams()[name]["t"]
        inside = (t >= 0.5) & (t <= 1.5)
        np.testing.assert_array_equal(w.streams()[name]["t"], t[inside], err_msg=name)
    np.testing.assert_array_equal(w.tdoa["tdoa"], f.tdoa["tdoa"][(f.tdoa["t"] >= 0.5) & (f.tdoa["t"] <= 1.5)])
    assert 0.5 <= w.time_span()[0] and w.time_span()[1] <= 1.5
    # AND a reversed or non-finite window is a ValueError
    for t0, t1 in ((1.5, 0.5), (float("nan"), 1.0)):
        with pytest.raises(ValueError, match="t0 < t1"):
            f.window(t0, t1)


def test_flight_csv_round_trip_reproduces_the_arrays(tmp_path):
    # GIVEN a flight with values representable in the file's precision
    rng = np.random.default_rng(2)
    f = _synthetic_flight(rng)
    f.tdoa = {**f.tdoa, "tdoa": np.round(f.tdoa["tdoa"], 4)}
    # WHEN it is written and read back
    path = tmp_path / "flight.csv"
    u.write_flight_csv(f, str(path))
    g = u.read_flight_csv(str(path))
    # THEN each stream matches (the file stores float32-like precision: %.7g)
    for name in ("tdoa", "acc", "gyro", "pose"):
        a, b = f.streams()[name], g.streams()[name]
        assert set(a) == set(b), name
        for key in a:
            np.testing.assert_allclose(b[key], a[key], rtol=2e-6, atol=2e-6, err_msg=f"{name}.{key}")


def test_malformed_flight_csv_raises_value_error_with_file_and_line(tmp_path):
    path = tmp_path / "bad.csv"
    path.write_text("t_tdoa,idA,idB,tdoa_meas\n0.1,0,1,0.5\n0.2,0,1,abc\n")
    with pytest.raises(ValueError, match=r"bad\.csv:3:\d+"):
        u.read_flight_csv(str(path))


def test_missing_file_raises_os_error(tmp_path):
    with pytest.raises(OSError, match="missing.csv"):
        u.read_flight_csv(str(tmp_path / "missing.csv"))
    with pytest.raises(OSError):
        u.read_anchor_survey(str(tmp_path / "missing_survey.txt"))


def test_unknown_required_stream_and_bad_shapes_raise_value_error():
    with pytest.raises(ValueError, match="unknown stream 'imu'"):
        u.read_flight_csv("x.csv", required=["imu"])
    with pytest.raises(ValueError, match=r"acc\['value'\]: expected shape \(N, 3\)"):
        u.Flight(acc={"t": np.zeros(4), "value": np.zeros((4, 2))})
    with pytest.raises(ValueError, match="missing key 'tdoa'"):
        u.Flight(tdoa={"t": np.zeros(2), "id_a": [0, 1], "id_b": [1, 2]})


def test_anchor_survey_round_trip(tmp_path):
    rng = np.random.default_rng(3)
    q = rng.normal(size=(5, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    s = u.AnchorSurvey(ids=[4, 0, 1, 2, 3], positions=rng.normal(0, 3, (5, 3)), quaternions=q)
    assert list(s.ids) == [0, 1, 2, 3, 4] and len(s) == 5 and 3 in s
    path = tmp_path / "survey.txt"
    u.write_anchor_survey(s, str(path))
    r = u.read_anchor_survey(str(path))
    np.testing.assert_array_equal(r.ids, s.ids)
    np.testing.assert_allclose(r.positions, s.positions, atol=1e-9)
    np.testing.assert_allclose(r.positions_of([2, 2, 4]), s.positions[[2, 2, 4]], atol=1e-9)
    with pytest.raises(KeyError):
        r.position(9)


def test_predict_tdoa_matches_numpy_and_features_have_the_documented_shapes():
    rng = np.random.default_rng(4)
    n = 100
    p = rng.normal(0, 1, (n, 3))
    yaw = rng.uniform(-np.pi, np.pi, n)
    q = np.column_stack([np.zeros(n), np.zeros(n), np.sin(yaw / 2), np.cos(yaw / 2)])  # (x, y, z, w)
    a, b = np.array([3.0, -4.0, 0.2]), np.array([-3.0, 4.0, 2.9])
    tag = u.UTIL_TAG_OFFSET_B
    rot_tag = np.column_stack([np.cos(yaw) * tag[0] - np.sin(yaw) * tag[1], np.sin(yaw) * tag[0] + np.cos(yaw) * tag[1],
                               np.full(n, tag[2])])
    p_tag = p + rot_tag
    expected = np.linalg.norm(p_tag - b, axis=1) - np.linalg.norm(p_tag - a, axis=1)
    np.testing.assert_allclose(u.predict_tdoa(p, q, a, b), expected, atol=1e-12)
    f = u.make_tdoa_features(0, 1, p, q, a, b)
    assert f["b_p_a"].shape == (n, 3) and f["yaw_a"].shape == (n,) and list(np.unique(f["id_b"])) == [1]
    # the anchor's azimuth in the body frame is its world azimuth minus the body yaw (level flight)
    d = a - p
    expected_yaw = np.angle(np.exp(1j * (np.arctan2(d[:, 1], d[:, 0]) - yaw)))
    np.testing.assert_allclose(np.angle(np.exp(1j * (f["yaw_a"] - expected_yaw))), 0, atol=1e-9)
    with pytest.raises(ValueError, match="length mismatch"):
        u.predict_tdoa(p, q[:10], a, b)


def test_real_flight_reads_into_arrays_and_matches_the_model():
    flight = u.read_flight_csv(str(pilot_flight("0425-traj2")), required=["tdoa", "pose"])
    survey = u.read_anchor_survey(str(pilot_survey("0425")))
    tdoa, pose = flight.tdoa, flight.pose
    assert tdoa["t"].size > 10_000 and flight.pose_has_orientation
    # TDoA residual against the ground truth (nearest pose sample) is small in flight
    i = np.clip(np.searchsorted(pose["t"], tdoa["t"]), 0, pose["t"].size - 1)
    airborne = pose["p"][i, 2] > 0.5
    z = u.predict_tdoa(pose["p"][i], pose["q"][i], survey.positions_of(tdoa["id_a"]), survey.positions_of(tdoa["id_b"]))
    assert np.median(np.abs(tdoa["tdoa"] - z)[airborne]) < 0.3


def test_trajectory_csv_round_trip(tmp_path):
    rng = np.random.default_rng(5)
    n = 30
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    traj = {"t": np.arange(n) * 0.01, "p": rng.normal(size=(n, 3)), "q": q,
            "sigma_p": rng.uniform(0.01, 0.5, (n, 3)), "v": rng.normal(size=(n, 3))}
    path = tmp_path / "traj.csv"
    u.write_trajectory_csv(traj, str(path))
    back = u.read_trajectory_csv(str(path))
    for key in traj:
        np.testing.assert_allclose(back[key], traj[key], rtol=1e-6, atol=1e-6, err_msg=key)
    with pytest.raises(ValueError, match=r"trajectory\['p'\]"):
        u.write_trajectory_csv({"t": np.zeros(3), "p": np.zeros((2, 3))}, str(path))


def test_malformed_survey_raises_value_error_naming_the_file(tmp_path):
    path = tmp_path / "survey.txt"
    path.write_text("an0_p,1.0,2.0,oops\n")
    with pytest.raises(ValueError, match=r"survey\.txt:1"):
        u.read_anchor_survey(str(path))
