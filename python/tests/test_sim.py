"""uwbtdoa sim bindings and ground-truth residuals: a simulated flight as numpy arrays, with its truth."""
import numpy as np
import pytest

import uwbtdoa as u


@pytest.fixture(scope="module")
def sim():
    return u.simulate_flight("circle", 25.0, seed=5)


def test_simulated_flight_carries_every_stream_and_its_truth(sim):
    flight, truth = sim["flight"], sim["tdoa_truth"]
    assert {"tdoa", "acc", "gyro", "pose"} <= set(flight.present)
    tdoa = flight.tdoa
    assert truth["error"].shape == tdoa["tdoa"].shape
    # measured = true + error, exactly (S17)
    np.testing.assert_allclose(tdoa["tdoa"], truth["tdoa_true"] + truth["error"], atol=1e-9)
    assert 0.3 < truth["airborne"].mean() < 0.95
    assert len(sim["survey"]) == 8


def test_simulation_is_deterministic_per_seed_and_checks_its_parameters():
    a = u.simulate_flight("zigzag", 20.0, seed=9).get("flight").tdoa["tdoa"]
    b = u.simulate_flight("zigzag", 20.0, seed=9).get("flight").tdoa["tdoa"]
    np.testing.assert_array_equal(a, b)
    with pytest.raises(ValueError, match="unknown simulation parameter 'bias.nope'"):
        u.simulate_flight(params={"bias.nope": 1.0})
    with pytest.raises(ValueError, match="simulation parameter 'bias.burst_scale_m': wrong type"):
        u.simulate_flight(params={"bias.burst_scale_m": "big"})
    # the burst fields reach the simulator: no bursts and no spikes change the error
    calm = u.simulate_flight("zigzag", 20.0, seed=9, params={"bias.burst_probability": 0.0,
                                                              "bias.outlier_probability": 0.0})
    assert not np.array_equal(calm["flight"].tdoa["tdoa"], a)
    with pytest.raises(ValueError, match="unknown trajectory 'square'"):
        u.simulate_flight("square")


def test_flights_with_one_field_seed_share_the_learnable_bias():
    def pattern_mismatch(a, b):
        """RMS of a's pattern error minus b's, interpolated per anchor pair at a's times (airborne)."""
        ta, tb = a["flight"].tdoa, b["flight"].tdoa
        sq = []
        for pair in set(zip(ta["id_a"].tolist(), ta["id_b"].tolist())):
            ia = (ta["id_a"] == pair[0]) & (ta["id_b"] == pair[1]) & a["tdoa_truth"]["airborne"]
            ib = (tb["id_a"] == pair[0]) & (tb["id_b"] == pair[1])
            other = np.interp(ta["t"][ia], tb["t"][ib], b["tdoa_truth"]["pattern"][ib])
            sq.append((a["tdoa_truth"]["pattern"][ia] - other) ** 2)
        return float(np.sqrt(np.mean(np.concatenate(sq))))

    shared = {"bias.field_seed": 42}
    a = u.simulate_flight("circle", 25.0, seed=3, params=shared)
    b = u.simulate_flight("circle", 25.0, seed=4, params=shared)
    c = u.simulate_flight("circle", 25.0, seed=4)
    # the same drone in the same room: the pattern part is one function of the pose (up to interpolation)
    assert pattern_mismatch(a, b) < 0.01
    assert pattern_mismatch(a, c) > 0.03
    assert not np.array_equal(a["tdoa_truth"]["noise"], b["tdoa_truth"]["noise"][: a["tdoa_truth"]["noise"].size])


def test_noise_free_simulation_matches_the_measurement_model(sim):
    r = u.simulate_flight("circle", 22.0, seed=2, noise_free=True)
    f, s = r["flight"], r["survey"]
    tdoa, pose = f.tdoa, r["pose_exact"]
    res = u.tdoa_residuals(f, s)
    assert res["report"]["n_residuals"] > 0.9 * tdoa["t"].size
    # residuals against the interpolated (1 mm quantized) truth are at the millimetre level
    assert np.percentile(np.abs(res["residual"]), 99) < 0.01


def test_residuals_recover_the_simulated_bias(sim):
    res = u.tdoa_residuals(sim["flight"], sim["survey"])
    err = sim["tdoa_truth"]["error"][res["index"]]
    air = res["airborne"]
    assert np.corrcoef(res["residual"][air], err[air])[0, 1] > 0.95


def test_simulated_flight_round_trips_through_the_util_csv(sim, tmp_path):
    path = tmp_path / "sim.csv"
    u.write_flight_csv(sim["flight"], str(path))
    g = u.read_flight_csv(str(path), required=["tdoa", "acc", "gyro", "pose"], survey=sim["survey"])
    np.testing.assert_allclose(g.tdoa["tdoa"], sim["flight"].tdoa["tdoa"], rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(g.acc["value"], sim["flight"].acc["value"], rtol=1e-6, atol=1e-5)


def test_pose_track_interpolates_and_flags_missing_truth(sim):
    track = u.PoseTrack(sim["flight"])
    q = track.interpolate(np.array([-5.0, 10.0, 12.5]))
    assert list(q["valid"]) == [False, True, True]
    assert np.isnan(q["p"][0]).all()
    np.testing.assert_allclose(np.linalg.norm(q["q"][1:], axis=1), 1.0, atol=1e-12)
    with pytest.raises(ValueError, match="unknown PoseTrack parameter"):
        u.PoseTrack(sim["flight"], params={"gap": 1.0})


def test_tdoa3_schedule_pairs_every_anchor_with_every_other():
    # TDoA2: the eight neighbour pairs in round robin; TDoA3 (S19b): random pairs of distinct anchors, at its own rate
    tdoa2 = u.simulate_flight("circle", 25.0, seed=2)["flight"].tdoa
    sim3 = u.simulate_flight("circle", 25.0, seed=2, params={"tdoa.tdoa3": True, "tdoa.rate_hz": 200.0})
    tdoa3, truth = sim3["flight"].tdoa, sim3["tdoa_truth"]
    unordered = lambda t: {tuple(sorted(p)) for p in zip(t["id_a"].tolist(), t["id_b"].tolist())}
    assert len(unordered(tdoa2)) == 8
    assert len(unordered(tdoa3)) == 28
    assert np.all(tdoa3["id_a"] != tdoa3["id_b"])
    assert 0.45 < tdoa3["t"].size / tdoa2["t"].size < 0.55
    np.testing.assert_allclose(tdoa3["tdoa"], truth["tdoa_true"] + truth["error"], atol=1e-9)
    with pytest.raises(ValueError, match="'tdoa.tdoa3': wrong type"):
        u.simulate_flight(params={"tdoa.tdoa3": "yes"})
