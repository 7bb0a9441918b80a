#!/usr/bin/env python3
"""Airborne RMSE of the whole flight and of its second half, without and with a bias learned online (the antenna
pattern, docs/math/filter.md F25; the range-bias states, F27).

For each flight: `uwbtdoa localize FLIGHT --anchors SURVEY --json --out TRAJ [extra flags]` twice (the baseline flags,
then the same flags plus --antenna-bias-degree DEGREE); the estimate is interpolated linearly at the ground-truth
times (no comparison across estimate gaps over 0.1 s, as eval/TrajectoryMetrics), airborne = ground-truth z > 0.3 m
(io/Airborne.h), and the second half is the airborne samples after the middle of the first and last airborne time.

Usage: scripts/online_bias_eval.py BUILD_DIR SURVEY FLIGHT.csv... [-- flags of the learning run [-- flags of the
baseline run]]
e.g. the range-bias states (on by default) against the filter without them:
  scripts/online_bias_eval.py build SURVEY FLIGHTS -- -- --range-bias-sigma-m 0 --tdoa-sigma-m 0.35
"""
import json
import os
import subprocess
import sys
import tempfile

import numpy as np


def read_truth(path):
    with open(path) as f:
        header = f.readline().strip().split(",")
    cols = [header.index(c) for c in ("t_pose", "pose_x", "pose_y", "pose_z")]
    rows = []
    with open(path) as f:
        f.readline()
        for line in f:
            parts = line.rstrip("\n").split(",")
            try:
                vals = [float(parts[c]) for c in cols]
            except (ValueError, IndexError):
                continue
            rows.append(vals)
    a = np.array(rows)
    return a[:, 0], a[:, 1:4]


def rmse_parts(traj_path, t_true, p_true):
    est = np.genfromtxt(traj_path, delimiter=",", names=True)
    t_est = est["t"]
    p_est = np.stack([est["x"], est["y"], est["z"]], axis=1)
    inside = (t_true >= t_est[0]) & (t_true <= t_est[-1])
    t, p = t_true[inside], p_true[inside]
    k = np.clip(np.searchsorted(t_est, t), 1, len(t_est) - 1)
    gap_ok = (t_est[k] - t_est[k - 1]) <= 0.1
    w = (t - t_est[k - 1]) / np.maximum(t_est[k] - t_est[k - 1], 1e-12)
    q = p_est[k - 1] + w[:, None] * (p_est[k] - p_est[k - 1])
    air = (p[:, 2] > 0.3) & gap_ok
    err = np.linalg.norm(q - p, axis=1)
    ta = t[air]
    mid = 0.5 * (ta[0] + ta[-1])
    second = air & (t >= mid)
    return float(np.sqrt(np.mean(err[air] ** 2))), float(np.sqrt(np.mean(err[second] ** 2)))


def run(build, survey, flight, flags, tmpdir):
    out = os.path.join(tmpdir, "traj.csv")
    cmd = [os.path.join(build, "uwbtdoa"), "localize", flight, "--anchors", survey, "--json", "--out", out] + flags
    j = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
    t, p = read_truth(flight)
    whole, second = rmse_parts(out, t, p)
    return j["rmse_airborne_m"], whole, second, j["cpu_time_s"]


def main():
    args = sys.argv[1:]
    extra, base = [], []
    if "--" in args:
        i = args.index("--")
        args, extra = args[:i], args[i + 1:]
    if "--" in extra:
        i = extra.index("--")
        extra, base = extra[:i], extra[i + 1:]
    build, survey, flights = args[0], args[1], args[2:]
    print(f"{'flight':14s} {'tool_air':>8s} {'air_u':>7s} {'air_l':>7s} {'chg%':>6s} {'2nd_u':>7s} {'2nd_l':>7s} "
          f"{'chg%':>6s} {'cpu_u':>6s} {'cpu_l':>6s}")
    ch_whole, ch_second = [], []
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for f in flights:
            tool_u, wu, su, cu = run(build, survey, f, base, tmp)
            _, wl, sl, cl = run(build, survey, f, extra, tmp)
            cw, cs = 100 * (wl / wu - 1), 100 * (sl / su - 1)
            ch_whole.append(cw)
            ch_second.append(cs)
            rows.append((wu, wl, su, sl))
            name = os.path.basename(f).replace(".csv", "")
            print(f"{name:14s} {tool_u:8.3f} {wu:7.3f} {wl:7.3f} {cw:+6.1f} {su:7.3f} {sl:7.3f} {cs:+6.1f} "
                  f"{cu:6.3f} {cl:6.3f}")
    r = np.array(rows)
    med = np.median(r, axis=0)
    print(f"{'median':14s} {'':8s} {med[0]:7.3f} {med[1]:7.3f} {np.median(ch_whole):+6.1f} {med[2]:7.3f} "
          f"{med[3]:7.3f} {np.median(ch_second):+6.1f}")
    print(f"worst change: whole {max(ch_whole):+.1f} %, second half {max(ch_second):+.1f} %")


if __name__ == "__main__":
    main()
