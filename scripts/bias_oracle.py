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

Usage: scripts/bias_oracle.py [BUILD_DIR] [--span=S] [FLIGHT_NAME...]   (data: $UWBTDOA_DATA or ../shared/data; default: the
       16 TDoA2 development flights of util-pilot)
"""
import os
import subprocess
import sys
import tempfile

import numpy as np

# --span=S: the running mean's span for "fast" [s] (default 2)
SPAN = [float(a[len("--span="):]) for a in sys.argv[1:] if a.startswith("--span=")]
ARGS = [a for a in sys.argv[1:] if not a.startswith("--span=")]
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


def main():
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
