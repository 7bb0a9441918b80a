"""uwbtdoa.Estimator, the online estimator from Python: events pushed one at a time give localize_flight's
estimates on the same flight (docs/python.md, "Online estimation")."""
import numpy as np
import pytest

import uwbtdoa
from conftest import pilot_flight, pilot_survey


def _window(stream: dict, t0: float, t1: float) -> dict:
    keep = (stream["t"] >= t0) & (stream["t"] <= t1)
    return {k: v[keep] for k, v in stream.items()}


def _events(flight):
    """The merged events as localize_flight feeds them: IMU at the accelerometer stamps with the latest gyro sample
    at or before each (the first one before any), then TDoA; IMU first at equal stamps."""
    acc, gyro, tdoa = flight.acc, flight.gyro, flight.tdoa
    k = np.clip(np.searchsorted(gyro["t"], acc["t"], side="right") - 1, 0, None)
    imu = [(t, 0, i) for i, t in enumerate(acc["t"])]
    tof = [(t, 1, i) for i, t in enumerate(tdoa["t"])]
    for t, kind, i in sorted(imu + tof, key=lambda e: (e[0], e[1])):
        if kind == 0:
            yield t, ("imu", acc["value"][i], gyro["value"][k[i]])
        else:
            yield t, ("tdoa", int(tdoa["id_a"][i]), int(tdoa["id_b"][i]), tdoa["tdoa"][i])


def test_estimator_gives_localize_flight_estimates_on_a_short_flight():
    # GIVEN 5 s of a real flight in the air and its anchors
    full = uwbtdoa.read_flight_csv(str(pilot_flight("0425-traj1")))
    survey = uwbtdoa.read_anchor_survey(str(pilot_survey("0425")))
    short = uwbtdoa.Flight(acc=_window(full.acc, 12.0, 17.0), gyro=_window(full.gyro, 12.0, 17.0),
                           tdoa=_window(full.tdoa, 12.0, 17.0))
    batch = uwbtdoa.localize_flight(short, survey, output_period_s=0.01)["trajectory"]
    # WHEN the same events are pushed one at a time, an estimate taken at the batch path's cadence
    est = uwbtdoa.Estimator({}, {int(i): tuple(p) for i, p in zip(survey.ids, survey.positions)})
    out, t_last_out, t_end = [], -1e300, None
    for t, ev in _events(short):
        if ev[0] == "imu":
            est.add_imu(t, ev[1], ev[2])
        else:
            est.add_tdoa(t, ev[1], ev[2], ev[3])
        t_end = t
        if est.ready and t - t_last_out >= 0.01:
            out.append(est.estimate())
            t_last_out = t
    if est.ready and (not out or out[-1]["t"] < t_end):
        out.append(est.estimate())
    # THEN the same estimates: same stamps, positions within 1e-9 m
    assert len(out) > 400
    assert len(out) == len(batch["t"])
    np.testing.assert_array_equal([e["t"] for e in out], batch["t"])
    np.testing.assert_allclose(np.array([e["p"] for e in out]), batch["p"], rtol=0, atol=1e-9)
    e = out[-1]
    assert e["p"].shape == (3,) and e["q"].shape == (4,) and e["v"].shape == (3,)
    assert e["cov_pose"].shape == (6, 6)
    np.testing.assert_allclose(e["cov_pose"], e["cov_pose"].T, atol=1e-12)
    assert abs(np.linalg.norm(e["q"]) - 1.0) < 1e-9
    assert e["phase"] in ("ground", "acquisition", "tracking", "landed")


def test_estimator_refuses_too_few_anchors_and_bad_params():
    with pytest.raises(ValueError):
        uwbtdoa.Estimator({}, {0: (0.0, 0.0, 0.0), 1: (1.0, 0.0, 0.0)})
    with pytest.raises(ValueError):
        uwbtdoa.Estimator({"no_such_param": 1.0}, {i: (float(i), 0.0, 0.0) for i in range(4)})


def test_estimator_skips_and_counts_sensor_values_outside_their_range():
    # GIVEN an estimator on four anchors (filter.md F31: the gyro's range ‖ω‖ ≤ 70 rad/s, the TDoA's the baseline)
    anchors = {0: (-3.0, -3.0, 0.2), 1: (3.0, -3.0, 2.8), 2: (3.0, 3.0, 0.2), 3: (-3.0, 3.0, 2.8)}
    est = uwbtdoa.Estimator({}, anchors)
    # WHEN a level IMU sample, one with a gyro of 1e10 deg/s, one with a NaN accelerometer and a TDoA of 1e30 m arrive
    est.add_imu(0.0, (0.0, 0.0, 9.81), (0.0, 0.0, 0.0))
    est.add_imu(0.001, (0.0, 0.0, 9.81), (0.0, 0.0, np.radians(1e10)))
    est.add_imu(0.002, (np.nan, 0.0, 9.81), (0.0, 0.0, 0.0))
    est.add_tdoa(0.003, 0, 1, 1e30)
    # THEN the three bad ones are skipped and counted per sensor, with the warnings naming them
    r = est.summary["sensor_range"]
    assert (r["gyro"]["n"], r["acc"]["n"], r["tdoa"]["n"]) == (1, 1, 1)
    assert r["gyro"]["first_t_s"] == pytest.approx(0.001)
    assert r["gyro"]["limit"] == 70.0
    warnings = est.summary["sensor_range_warnings"]
    assert len(warnings) == 3 and "skipped 1 gyro sample" in warnings[0]
