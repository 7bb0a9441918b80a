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
A path the simulated quadrotor cannot fly (simulation.md S8') is refused by the simulator and counted as such.
Prints one line per run (airborne RMSE, whole-flight RMSE, largest error, re-acquisitions, TDoA used, the draw) and a
summary: median, worst, runs above 0.5 m airborne RMSE.

Usage: scripts/sim_sweep.py [BUILD_DIR] [--seed S] [--runs N] [--extreme]   (anchor presets: $UWBTDOA_DATA or
../shared/data for the util-* layouts)
"""
import json
import os
import random
import statistics
import subprocess
import sys
import tempfile


def option(args, name, default, kind):
    if name not in args:
        return default
    i = args.index(name)
    if i + 1 >= len(args):
        sys.exit(f"sim_sweep.py: {name} needs a value")
    try:
        value = kind(args[i + 1])
    except ValueError:
        sys.exit(f"sim_sweep.py: {name} {args[i + 1]}: not a {kind.__name__}")
    del args[i:i + 2]
    return value


ARGS = sys.argv[1:]
SEED = option(ARGS, "--seed", 11, int)
RUNS = option(ARGS, "--runs", 150, int)
EXTREME = "--extreme" in ARGS
ARGS = [a for a in ARGS if a != "--extreme"]
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


def main():
    if not os.path.isfile(CLI):
        sys.exit(f"sim_sweep.py: no {CLI} (build first, or pass the build directory)")
    rng = random.Random(SEED)
    rmse, refused, failed = [], 0, 0
    with tempfile.TemporaryDirectory() as tmp:
        flight, survey, config = (os.path.join(tmp, n) for n in ("f.csv", "s.txt", "c.json"))
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
            loc = subprocess.run([CLI, "localize", flight, "--anchors", survey, "--json", "--no-diagnostics"],
                                 capture_output=True, text=True)
            if loc.returncode != 0:
                failed += 1
                print(f"localize failed: {described}: {loc.stderr.strip()[:200]}")
                continue
            d = json.loads(loc.stdout)
            a, w = d["airborne"], d["whole"]
            rmse.append(a["rmse_m"])
            print(f"{a['rmse_m']:.3f} whole {w['rmse_m']:.3f} max {w['max_m']:.2f} reacq {d['n_reacquisitions']} "
                  f"used {d['n_tdoa_used'] / max(1, d['n_tdoa']):.2f} {described}", flush=True)
    if rmse:
        print(f"{len(rmse)} runs ({'extreme' if EXTREME else 'default'} family, seed {SEED}): airborne RMSE median "
              f"{statistics.median(rmse):.3f} m, worst {max(rmse):.3f} m, above 0.5 m: {sum(r > 0.5 for r in rmse)}; "
              f"refused by the simulator: {refused}; localize failed: {failed}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
