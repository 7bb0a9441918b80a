#!/usr/bin/env python3
"""A randomised sweep of simulated flights through `uwbtdoa localize` (docs/robustness.md, "a randomised sweep"):
flights the protocol does not hold, drawn at random, to find the filter's failures before a user does.

Each run draws a trajectory (zigzag, circle, circle-sine, figure8, hover), an anchor layout (paper, util-const1..4,
util-pilot-0425/0426), a seed and a yaw rate, simulates it (`uwbtdoa simulate`) and localizes it with the defaults
(`uwbtdoa localize --json --no-diagnostics`). Two families:
  default   30-90 s flights with the simulator's phases; 30 % in the TDoA3 mode, 20 % with the IMU at 100-500 Hz
  --extreme 20, 25 or 120 s flights; 0.5, 1 or 10 s on the ground before the take-off; take-offs of 1 or 1.5 s;
            fast patterns; heights 0.6 or 2.2 m; TDoA at 50-800 Hz; the IMU at 100 or 200 Hz; yaw rates 1.5 and
            2.5 rad/s; extra outliers and bursts (each drawn independently)
  --air     the default family's flights, each logged from a random instant of its first half in the air (`localize
            --window T0,T1`: every stream cut there) to the end of the log or to a random instant before the landing;
            the error 3-5 s after T0 is printed next to that of the same flight logged from the ground, same window
A path the simulated quadrotor cannot fly (simulation.md S8') is refused by the simulator and counted as such.
Prints one line per run (airborne RMSE, whole-flight RMSE, largest error, re-acquisitions, TDoA used, the draw) and a
summary: median, worst, runs above 0.5 m airborne RMSE; the whole flight's RMSE and largest error (take-off, landing).

Usage: scripts/sim_sweep.py [BUILD_DIR] [--seed S] [--runs N] [--extreme | --air]   (anchor presets: $UWBTDOA_DATA
or ../shared/data for the util-* layouts)
"""
import bisect
import csv
import json
import math
import os
import random
import statistics
import subprocess
import sys
import tempfile

from script_args import option


ARGS = sys.argv[1:]
SEED = option(ARGS, "--seed", 11, int)
RUNS = option(ARGS, "--runs", 150, int)
EXTREME = "--extreme" in ARGS
AIR = "--air" in ARGS
if EXTREME and AIR:
    sys.exit("sim_sweep.py: --extreme and --air are two families; choose one")
ARGS = [a for a in ARGS if a not in ("--extreme", "--air")]
BUILD = ARGS[0] if ARGS else "build"
CLI = os.path.join(BUILD, "uwbtdoa")
TRAJECTORIES = ["zigzag", "circle", "circle-sine", "figure8", "hover"]
LAYOUTS = ["paper", "util-const1", "util-const2", "util-const3", "util-const4", "util-pilot-0425", "util-pilot-0426"]


def draw(rng):
    """One run: (simulate arguments without the files, config object)."""
    traj, layout, seed = rng.choice(TRAJECTORIES), rng.choice(LAYOUTS), rng.randint(1, 10**6)
    cfg = {}
    if not EXTREME:
        yaw, duration = rng.choice([0, 0.2, 0.5, 1.0]), rng.choice([30, 45, 60, 90])
        if rng.random() < 0.3:
            cfg["tdoa"] = {"tdoa3": True, "rate_hz": 200}
        if rng.random() < 0.2:
            cfg["imu"] = {"rate_hz": rng.choice([100, 250, 500])}
    else:
        yaw, duration = rng.choice([0, 1.5, 2.5]), rng.choice([20, 25, 120])
        t = {}
        if rng.random() < 0.5:
            t["ground_before_s"] = rng.choice([0.5, 1.0, 10.0])
        if rng.random() < 0.5:
            t["takeoff_s"] = rng.choice([1.0, 1.5])
        if rng.random() < 0.5:
            t["omega_rps"] = rng.choice([1.2, 1.6])
            t["figure8_omega_rps"] = rng.choice([0.8, 1.0])
        if rng.random() < 0.3:
            t["height_m"] = rng.choice([0.6, 2.2])
        cfg["trajectory"] = t
        if rng.random() < 0.3:
            cfg["tdoa"] = {"rate_hz": rng.choice([50, 100, 800])}
        if rng.random() < 0.3:
            cfg["imu"] = {"rate_hz": rng.choice([100, 200])}
        if rng.random() < 0.3:
            cfg["bias"] = {"outlier_probability": 0.05, "burst_probability": 0.02}
    args = ["--trajectory", traj, "--duration", str(duration), "--seed", str(seed), "--anchors-preset", layout,
            "--yaw-rate", str(yaw)]
    return args, cfg


def read_pose(flight_csv):
    """(t, [x, y, z]) of the simulated flight's ground-truth pose (the t_pose, pose_x/y/z columns)."""
    t, p = [], []
    with open(flight_csv, newline="") as f:
        rows = csv.reader(f)
        head = next(rows)
        it, ix = head.index("t_pose"), [head.index(c) for c in ("pose_x", "pose_y", "pose_z")]
        for r in rows:
            if len(r) > it and r[it]:
                t.append(float(r[it]))
                p.append([float(r[i]) for i in ix])
    return t, p


def window_rmse(traj_csv, pose, a, b):
    """3D RMSE of the estimate (`localize --out`) against the pose at its stamps in [a, b]; None without samples."""
    t, p = pose
    sq = []
    with open(traj_csv, newline="") as f:
        rows = csv.reader(f)
        next(rows)
        for r in rows:
            te = float(r[0])
            if te < a or te > b:
                continue
            k = min(max(bisect.bisect_left(t, te), 1), len(t) - 1)
            w = (te - t[k - 1]) / (t[k] - t[k - 1]) if t[k] > t[k - 1] else 0.0
            sq.append(sum((float(r[1 + i]) - ((1 - w) * p[k - 1][i] + w * p[k][i])) ** 2 for i in range(3)))
    return math.sqrt(sum(sq) / len(sq)) if sq else None


def air_window(pose, rng):
    """A log started in the air: T0 in the first half of the airborne span (from 1 s after the body is 0.3 m above
    its first height), T1 the end of the log or a random instant of the last quarter before the landing."""
    t, p = pose
    z0 = p[0][2]
    air = [ti for ti, pi in zip(t, p) if pi[2] > z0 + 0.3]
    if len(air) < 2 or air[-1] - air[0] < 10.0:
        return None
    span = air[-1] - air[0]
    t0 = rng.uniform(air[0] + 1.0, air[0] + 0.5 * span)
    t1 = t[-1] if rng.random() < 0.5 else rng.uniform(air[-1] - 0.25 * span, air[-1])
    return t0, t1


def localize(flight, survey, extra):
    return subprocess.run([CLI, "localize", flight, "--anchors", survey, "--json", "--no-diagnostics", *extra],
                          capture_output=True, text=True)


def main():
    if not os.path.isfile(CLI):
        sys.exit(f"sim_sweep.py: no {CLI} (build first, or pass the build directory)")
    rng = random.Random(SEED)
    rmse, refused, failed, early = [], 0, 0, []
    whole_rmse, whole_max = [], []
    with tempfile.TemporaryDirectory() as tmp:
        flight, survey, config, traj, traj_whole = (
            os.path.join(tmp, n) for n in ("f.csv", "s.txt", "c.json", "t.csv", "w.csv"))
        for _ in range(RUNS):
            args, cfg = draw(rng)
            with open(config, "w") as f:
                json.dump(cfg, f)
            described = " ".join(args) + " " + json.dumps(cfg)
            sim = subprocess.run([CLI, "simulate", *args, "--config", config, "--out", flight, "--survey-out", survey],
                                 capture_output=True, text=True)
            if sim.returncode != 0:
                refused += 1
                print(f"refused by the simulator: {described}: {sim.stderr.strip().splitlines()[-1][:160]}")
                continue
            extra, window = [], ""
            if AIR:
                pose = read_pose(flight)
                span = air_window(pose, rng)
                if span is None:
                    refused += 1
                    print(f"no air start possible (under 10 s in the air): {described}")
                    continue
                extra = ["--window", f"{span[0]:.3f},{span[1]:.3f}", "--out", traj]
            loc = localize(flight, survey, extra)
            if AIR and loc.returncode == 0:
                whole = localize(flight, survey, ["--out", traj_whole])
                e_cut = window_rmse(traj, pose, span[0] + 3.0, span[0] + 5.0)
                e_whole = window_rmse(traj_whole, pose, span[0] + 3.0, span[0] + 5.0)
                early.append(e_cut)
                window = (f"from {span[0]:.1f} to {span[1]:.1f} s: 3-5 s after the start {e_cut:.3f} (from the ground "
                          f"{e_whole:.3f}) ")
            if loc.returncode != 0:
                failed += 1
                print(f"localize failed: {described}: {loc.stderr.strip()[:200]}")
                continue
            d = json.loads(loc.stdout)
            a, w = d["airborne"], d["whole"]
            rmse.append(a["rmse_m"])
            whole_rmse.append(w["rmse_m"])
            whole_max.append(w["max_m"])
            print(f"{a['rmse_m']:.3f} whole {w['rmse_m']:.3f} max {w['max_m']:.2f} reacq {d['n_reacquisitions']} "
                  f"used {d['n_tdoa_used'] / max(1, d['n_tdoa']):.2f} {window}{described}", flush=True)
    if rmse:
        family = "extreme" if EXTREME else "air-start" if AIR else "default"
        print(f"{len(rmse)} runs ({family} family, seed {SEED}): airborne RMSE median "
              f"{statistics.median(rmse):.3f} m, worst {max(rmse):.3f} m, above 0.5 m: {sum(r > 0.5 for r in rmse)}; "
              f"refused by the simulator: {refused}; localize failed: {failed}")
        print(f"whole flight (take-off, landing, ground): RMSE median {statistics.median(whole_rmse):.3f} m, worst "
              f"{max(whole_rmse):.3f} m; largest error median {statistics.median(whole_max):.2f} m, worst "
              f"{max(whole_max):.2f} m, above 1 m: {sum(m > 1.0 for m in whole_max)}")
        if early:
            print(f"RMSE 3-5 s after the start in the air: median {statistics.median(early):.3f} m, worst "
                  f"{max(early):.3f} m, above 0.3 m: {sum(e > 0.3 for e in early)} of {len(early)}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
