#!/usr/bin/env python3
"""What a bias learner could at best take out: the filter on flights whose TDoA are corrected by parts of their true
error, known from the motion-capture pose (docs/math/filter.md F27f).

For each flight the TDoA error ε = z − h(p_gt) (paper eq. 6, `uwbtdoa.tdoa_residuals`) of the airborne measurements
(|ε| < 1 m) is split three ways, and the flight is localized with each part removed from its TDoA:
  full   all of ε (a perfect bias model);
  perp   ε minus its least-squares position-like part g·δp per 0.1 s window (g = u_B − u_A, u the unit vector from
         an anchor to the body): the part no position shift explains, which the innovations show at once;
  fast   ε minus its own running mean over S = 2 s (--span=S) per anchor pair: what varies faster than the body moves through the room,
         the part the IMU can tell from a position error (F27d iii).
Each run uses the filter without the range-bias states (--range-bias-sigma-m 0 --tdoa-sigma-m 0.35, the reference
of F27's online learning), and "online" is the default filter (the states) on the uncorrected flight. Printed: the
airborne RMSE over the second half of each flight (scripts/online_bias_eval.py's definition) and its change against
the reference, then the median and worst change per session.

With --imu, instead: how far the accelerometer alone carries the position (what it can tell from a TDoA bias that
changes over that time). From 100 airborne starts per flight, the Vicon position and velocity (±25 ms central
difference) are dead-reckoned with the logged specific force turned by the Vicon attitude, less gravity and less the
flight's best constant world-frame acceleration offset; printed: the RMS horizontal and vertical error after 0.5, 1
and 2 s. Meaningful only where the Vicon body frame is the IMU's (0426; on 0425 the offset is 2.2–2.3 m/s²).

Usage: scripts/bias_oracle.py [BUILD_DIR] [--span=S | --imu] [FLIGHT_NAME...]   (data: $UWBTDOA_DATA or ../shared/data; default: the
       16 TDoA2 development flights of util-pilot)
"""
import os
import subprocess
import sys
import tempfile

import numpy as np

# --span=S: the running mean's span for "fast" [s] (default 2)
SPAN = [float(a[len("--span="):]) for a in sys.argv[1:] if a.startswith("--span=")]
IMU = "--imu" in sys.argv[1:]
ARGS = [a for a in sys.argv[1:] if not a.startswith("--span=") and a != "--imu"]
BUILD = ARGS[0] if ARGS else "build"
sys.path.insert(0, os.path.join(BUILD, "python"))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import uwbtdoa  # noqa: E402
from online_bias_eval import read_truth, rmse_parts  # noqa: E402

DATA = os.environ.get("UWBTDOA_DATA") or os.path.join(os.path.dirname(__file__), "..", "..", "shared", "data")
PILOT = os.path.join(DATA, "real", "util-pilot")
FLIGHTS = ARGS[1:] or [f"0425-traj{i}" for i in range(1, 13)] + [f"0426-traj{i}" for i in (1, 2, 11, 12)]
REFERENCE = ["--range-bias-sigma-m", "0", "--tdoa-sigma-m", "0.35"]
WINDOW_S = 0.1     # the window of the position-like fit
RUNNING_S = SPAN[-1] if SPAN else 2.0  # the span of the running mean that "fast" removes


def parts(flight, survey):
    """Per TDoA of the flight (index into flight.tdoa): the corrections full, perp and fast (0 where not airborne)."""
    r = uwbtdoa.tdoa_residuals(flight, survey)
    n = len(flight.tdoa["t"])
    idx, t, a, b, eps = r["index"], r["t"], r["id_a"], r["id_b"], r["residual"]
    good = r["airborne"] & (np.abs(eps) < 1.0)
    idx, t, a, b, eps, p = idx[good], t[good], a[good], b[good], eps[good], r["w_p_b"][good]
    pa = np.array([survey.position(int(i)) for i in a])
    pb = np.array([survey.position(int(i)) for i in b])
    g = (p - pb) / np.linalg.norm(p - pb, axis=1)[:, None] - (p - pa) / np.linalg.norm(p - pa, axis=1)[:, None]
    perp = np.zeros_like(eps)
    window = np.floor(t / WINDOW_S).astype(int)
    for w in np.unique(window):
        s = window == w
        if s.sum() < 5:
            continue
        dp, *_ = np.linalg.lstsq(g[s], eps[s], rcond=None)
        perp[s] = eps[s] - g[s] @ dp
    fast = np.zeros_like(eps)
    for pair in set(zip(a.tolist(), b.tolist())):
        s = np.where((a == pair[0]) & (b == pair[1]))[0]
        ts, c = t[s], np.r_[0.0, np.cumsum(eps[s])]
        lo, hi = np.searchsorted(ts, ts - RUNNING_S / 2), np.searchsorted(ts, ts + RUNNING_S / 2)
        fast[s] = eps[s] - (c[hi] - c[lo]) / (hi - lo)
    out = {}
    for name, corr in (("full", eps), ("perp", perp), ("fast", fast)):
        full = np.zeros(n)
        full[idx] = corr
        out[name] = full
    return out


def second_half(path, survey_path, flags, truth, tmp):
    traj = os.path.join(tmp, "traj.csv")
    subprocess.run([os.path.join(BUILD, "uwbtdoa"), "localize", path, "--anchors", survey_path, "--out", traj, *flags],
                   check=True, capture_output=True)
    return rmse_parts(traj, *truth)[1]


def rotation(q):
    """Body-to-world rotation matrices of quaternions (N, 4) in (x, y, z, w)."""
    x, y, z, w = q.T
    return np.stack([np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
                     np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
                     np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1)], -2)


def dead_reckoning(name):
    session = name.split("-")[0]
    flight = uwbtdoa.read_flight_csv(os.path.join(PILOT, session, name + ".csv"))
    pose, acc = flight.pose, flight.acc
    tp, p, t, f_b = pose["t"], pose["p"], acc["t"], acc["value"]
    h = 0.025
    pos = np.stack([np.interp(t, tp, p[:, k]) for k in range(3)], 1)
    vel = np.stack([(np.interp(t + h, tp, p[:, k]) - np.interp(t - h, tp, p[:, k])) / (2 * h) for k in range(3)], 1)
    nearest = np.clip(np.searchsorted(tp, t), 0, len(tp) - 1)
    a_w = np.einsum("nij,nj->ni", rotation(pose["q"][nearest]), f_b) - np.array([0.0, 0.0, 9.81])
    dvdt = np.stack([(np.interp(t + 2 * h, t, vel[:, k]) - np.interp(t - 2 * h, t, vel[:, k])) / (4 * h)
                     for k in range(3)], 1)
    air = pos[:, 2] > 0.5
    offset = np.mean((a_w - dvdt)[air], 0)
    a_w -= offset
    starts = np.where(air)[0][:: max(1, air.sum() // 100)]
    dt_mean = float(np.median(np.diff(t)))
    cells = []
    for horizon in (0.5, 1.0, 2.0):
        n = int(horizon / dt_mean)
        err = []
        for i0 in starts:
            if i0 + n >= len(t) or not air[i0:i0 + n].all():
                continue
            steps = np.diff(t[i0:i0 + n + 1])
            v = vel[i0] + np.r_[np.zeros((1, 3)), np.cumsum(a_w[i0:i0 + n] * steps[:, None], 0)]
            p_end = pos[i0] + np.sum(v[:-1] * steps[:, None] + 0.5 * a_w[i0:i0 + n] * (steps ** 2)[:, None], 0)
            err.append(p_end - pos[i0 + n])
        e = np.array(err)
        cells.append(f"{horizon:.1f} s: xy {np.sqrt(np.mean(e[:, 0] ** 2 + e[:, 1] ** 2)):.3f} m, "
                     f"z {np.sqrt(np.mean(e[:, 2] ** 2)):.3f} m")
    print(f"{name:12s} offset {np.array2string(offset, precision=2)} m/s²; " + "; ".join(cells), flush=True)


def main():
    if IMU:
        for name in FLIGHTS:
            dead_reckoning(name)
        return
    runs = ("reference", "online", "full", "perp", "fast")
    print(f"{'flight':12s} " + " ".join(f"{r:>17s}" for r in runs))
    change = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name in FLIGHTS:
            session = name.split("-")[0]
            path = os.path.join(PILOT, session, name + ".csv")
            survey_path = os.path.join(PILOT, "survey", f"anchor_{session}_survey.txt")
            flight, survey = uwbtdoa.read_flight_csv(path), uwbtdoa.read_anchor_survey(survey_path)
            truth = read_truth(path)
            rmse = {"reference": second_half(path, survey_path, REFERENCE, truth, tmp),
                    "online": second_half(path, survey_path, [], truth, tmp)}
            tdoa = flight.tdoa
            for part, corr in parts(flight, survey).items():
                corrected = dict(tdoa)
                corrected["tdoa"] = tdoa["tdoa"] - corr
                flight.tdoa = corrected
                cpath = os.path.join(tmp, "corrected.csv")
                uwbtdoa.write_flight_csv(flight, cpath)
                rmse[part] = second_half(cpath, survey_path, REFERENCE, truth, tmp)
            flight.tdoa = tdoa
            change[name] = {r: 100 * (rmse[r] / rmse["reference"] - 1) for r in runs}
            print(f"{name:12s} " + " ".join(f"{rmse[r]:7.3f} ({change[name][r]:+6.1f} %)" for r in runs), flush=True)
    for session in sorted({n.split("-")[0] for n in FLIGHTS}):
        rows = [change[n] for n in FLIGHTS if n.startswith(session)]
        cells = [f"{np.median([c[r] for c in rows]):+6.1f} / {max(c[r] for c in rows):+6.1f}" for r in runs[1:]]
        print(f"{session}: median / worst change of the second half vs reference, " +
              ", ".join(f"{r} {c} %" for r, c in zip(runs[1:], cells)))


if __name__ == "__main__":
    main()
