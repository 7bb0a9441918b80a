#!/usr/bin/env python3
"""Real flights logged from random instants (docs/robustness.md, "Real flights logged from random instants").

The protocol cuts each dev flight at 5, 10 and 20 s; a user's log starts wherever the logging was switched on. This
draws, for every util-pilot flight, windows [T0, T1] at random (T0 from 1 s to 8 s before the end of the TDoA stream,
T1 at least 6 s later, possibly past the end: the landing included), localizes each with the defaults
(`uwbtdoa localize --window T0,T1 --json --no-diagnostics`: every stream cut there, as a log begun and ended then),
and prints one line per window: airborne RMSE and largest airborne error of the window, the same for the whole flight
localized once and evaluated over the same window, whether the start was in motion and whether its floor was refuted
(filter.md F16j). The summary gives median, 90th percentile and worst of both, and the windows whose largest error
exceeds the whole flight's by more than 0.5 m.

Usage: scripts/real_window_sweep.py BUILD_DIR [--seed S] [--per-flight N] [--data DIR]
       (data: $UWBTDOA_DATA or ../shared/data)
"""
import csv
import glob
import json
import math
import os
import random
import statistics
import subprocess
import sys
import tempfile

from script_args import option


def column(path, name, width):
    """The rows of the column-stacked stream that starts at column `name` (UTIL layout), `width` columns wide."""
    rows = []
    with open(path, newline="") as f:
        reader = csv.reader(f)
        header = next(reader)
        if name not in header:
            sys.exit(f"real_window_sweep.py: {path}: no column {name}")
        i = header.index(name)
        for line, row in enumerate(reader, start=2):
            if len(row) <= i or row[i] == "":
                continue
            try:
                rows.append([float(v) for v in row[i:i + width]])
            except ValueError:
                sys.exit(f"real_window_sweep.py: {path}:{line}: {name}: not a number")
    return rows


def interpolate(ts, values, t):
    """Linear interpolation of a sorted time series; None outside it."""
    if not ts or t < ts[0] or t > ts[-1]:
        return None
    lo, hi = 0, len(ts) - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if ts[mid] <= t:
            lo = mid
        else:
            hi = mid
    if ts[hi] == ts[lo]:
        return values[lo]
    w = (t - ts[lo]) / (ts[hi] - ts[lo])
    return [a + w * (b - a) for a, b in zip(values[lo], values[hi])]


def window_errors(trajectory_csv, pose_t, pose_p, t0, t1):
    """Airborne (true z > 0.3 m) RMSE and largest 3D error of a trajectory CSV over [t0, t1]; None without samples."""
    sq, worst = [], 0.0
    with open(trajectory_csv, newline="") as f:
        for row in csv.DictReader(f):
            t = float(row["t"])
            if t < t0 or t > t1:
                continue
            truth = interpolate(pose_t, pose_p, t)
            if truth is None or truth[2] <= 0.3:
                continue
            e = math.dist((float(row["x"]), float(row["y"]), float(row["z"])), truth)
            sq.append(e * e)
            worst = max(worst, e)
    if not sq:
        return None
    return math.sqrt(sum(sq) / len(sq)), worst


def localize(cli, flight, survey, out, window=None):
    cmd = [cli, "localize", flight, "--anchors", survey, "--out", out, "--json", "--no-diagnostics"]
    if window:
        cmd += ["--window", f"{window[0]:.2f},{window[1]:.2f}"]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        return None, r.stderr.strip().splitlines()[-1] if r.stderr.strip() else f"exit {r.returncode}"
    return json.loads(r.stdout), None


def main(args):
    if not args or args[0].startswith("-"):
        sys.exit(__doc__)
    cli = os.path.join(args[0], "uwbtdoa")
    if not os.path.exists(cli):
        sys.exit(f"real_window_sweep.py: {cli} not found (build the uwbtdoa target)")
    seed = option(args, "--seed", 1, int)
    per_flight = option(args, "--per-flight", 8, int)
    data = option(args, "--data", os.environ.get("UWBTDOA_DATA", "../shared/data"), str)
    pilot = os.path.join(data, "real", "util-pilot")
    flights = sorted(glob.glob(os.path.join(pilot, "04*", "*.csv")))
    if not flights:
        sys.exit(f"real_window_sweep.py: no util-pilot flights under {pilot}")
    rng = random.Random(seed)
    rows, failed = [], 0
    with tempfile.TemporaryDirectory() as tmp:
        whole_out, cut_out = os.path.join(tmp, "whole.csv"), os.path.join(tmp, "cut.csv")
        for flight in flights:
            name = os.path.splitext(os.path.basename(flight))[0]
            survey = os.path.join(pilot, "survey", f"anchor_{name[:4]}_survey.txt")
            pose = column(flight, "t_pose", 4)
            pose_t, pose_p = [r[0] for r in pose], [r[1:4] for r in pose]
            t_end = max(r[0] for r in column(flight, "t_tdoa", 1))
            whole, err = localize(cli, flight, survey, whole_out)
            if whole is None:
                print(f"{name}: whole flight failed: {err}")
                failed += 1
                continue
            for _ in range(per_flight):
                t0 = rng.uniform(1.0, t_end - 8.0)
                t1 = rng.uniform(t0 + 6.0, t_end + 2.0)
                run, err = localize(cli, flight, survey, cut_out, (t0, t1))
                if run is None:
                    print(f"{name} {t0:6.2f}-{t1:6.2f}: failed: {err}")
                    failed += 1
                    continue
                cut = window_errors(cut_out, pose_t, pose_p, t0, t1)
                ref = window_errors(whole_out, pose_t, pose_p, t0, t1)
                if cut is None or ref is None:
                    continue
                rows.append((name, t0, t1, *cut, *ref, run["started_in_motion"], run["start_floor_refuted"]))
                print(f"{name:12s} {t0:6.2f}-{t1:6.2f} s: RMSE {cut[0]:.3f} max {cut[1]:.2f} m | whole flight, same "
                      f"window: {ref[0]:.3f} / {ref[1]:.2f} m | in motion {run['started_in_motion']}, floor refuted "
                      f"{run['start_floor_refuted']}", flush=True)
    if not rows:
        sys.exit("real_window_sweep.py: no window with airborne samples")

    def stats(values):
        s = sorted(values)
        return statistics.median(s), s[min(len(s) - 1, int(0.9 * len(s)))], s[-1]

    print(f"\n{len(rows)} windows (seed {seed}, {per_flight} per flight), {failed} failed")
    for label, k in (("airborne RMSE", 3), ("largest airborne error", 4)):
        c, w = stats([r[k] for r in rows]), stats([r[k + 2] for r in rows])
        print(f"{label}: median / p90 / worst {c[0]:.3f} / {c[1]:.3f} / {c[2]:.3f} m "
              f"(whole flight, same windows: {w[0]:.3f} / {w[1]:.3f} / {w[2]:.3f} m)")
    worse = [r for r in rows if r[4] > r[6] + 0.5]
    print(f"windows whose largest error exceeds the whole flight's by more than 0.5 m: {len(worse)}")
    for r in sorted(worse, key=lambda r: r[6] - r[4])[:10]:
        print(f"  {r[0]} {r[1]:.2f}-{r[2]:.2f} s: {r[4]:.2f} m against {r[6]:.2f} m")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
