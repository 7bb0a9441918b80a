#!/usr/bin/env python3
"""What a log that starts in the air lacks at its first fix, against the whole flight at the same instant
(docs/results.md, "where the 20 s gap lies").

Each util-pilot flight with IMU is cut to start at T s (`uwbtdoa protocol --no-sim --cuts T --write-cuts DIR`: the cut
as the protocol runs it, ending 1 s before the last airborne instant), then the cut and the whole flight are localized
(`uwbtdoa localize ... --out`, which writes the velocity and the IMU biases the filter estimated). At the cut's first
output (its fix) the script prints, against the Vicon pose: the vertical velocity error (truth: central difference of
the Vicon height over +-0.1 s) and the height error of the cut and of the whole flight, the whole flight's thrust-axis
accelerometer bias there, and the cut's 2 and 5 s later next to the whole flight's at +5 s.

Usage: scripts/cut_start.py [BUILD_DIR] [--cut T]   (data: $UWBTDOA_DATA or ../shared/data)
"""
import csv
import glob
import os
import subprocess
import sys
import tempfile

import numpy as np

ARGS = sys.argv[1:]
CUT = "20"
if "--cut" in ARGS:
    i = ARGS.index("--cut")
    if i + 1 >= len(ARGS):
        sys.exit("cut_start.py: --cut needs a start time in seconds")
    CUT = ARGS[i + 1]
    del ARGS[i:i + 2]
BUILD = ARGS[0] if ARGS else "build"
CLI = os.path.join(BUILD, "uwbtdoa")
DATA = os.environ.get("UWBTDOA_DATA", os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared",
                                                   "data"))
PILOT = os.path.join(DATA, "real", "util-pilot")


def vicon_height(flight_csv):
    """(t, z) of the Vicon pose of a UTIL flight CSV (column-stacked: the pose rows are those with a t_pose)."""
    with open(flight_csv, newline="") as f:
        rows = csv.reader(f)
        head = next(rows)
        it, iz = head.index("t_pose"), head.index("pose_z")
        tz = [(float(r[it]), float(r[iz])) for r in rows if len(r) > iz and r[it] != ""]
    if not tz:
        sys.exit(f"cut_start.py: {flight_csv} has no Vicon pose")
    return np.array(tz).T


def trajectory(out_csv):
    t = np.genfromtxt(out_csv, delimiter=",", names=True)
    if "acc_bias_z" not in t.dtype.names:
        sys.exit(f"cut_start.py: {out_csv} has no IMU-bias columns (a TDoA-only run?)")
    return t


def at(traj, t, key):
    return float(np.interp(t, traj["t"], traj[key]))


def localize(flight, survey, out):
    subprocess.run([CLI, "localize", flight, "--anchors", survey, "--out", out, "--no-diagnostics"], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def main():
    if not os.path.isdir(PILOT):
        sys.exit(f"cut_start.py: no util-pilot data under {PILOT} (set UWBTDOA_DATA)")
    with tempfile.TemporaryDirectory() as tmp:
        cuts = os.path.join(tmp, "cuts")
        subprocess.run([CLI, "protocol", "--no-sim", "--cuts", CUT, "--write-cuts", cuts], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        rows = []
        print(f"cut at {CUT} s: errors at the cut's fix (cut / whole flight); thrust-axis accelerometer bias [m/s^2]")
        print(f"{'flight':12s} {'fix [s]':>7s} {'vz err [m/s]':>13s} {'z err [m]':>13s} {'b_z whole':>9s} "
              f"{'cut +2 s':>8s} {'cut +5 s':>8s} {'whole +5 s':>10s}")
        for cut in sorted(glob.glob(os.path.join(cuts, f"*-cut{CUT}.csv"))):
            name = os.path.basename(cut)[:-len(f"-cut{CUT}.csv")]
            session = name.split("-")[0]
            whole = os.path.join(PILOT, session, name + ".csv")
            if not os.path.isfile(whole):
                continue  # a flight without IMU (util-final-extract) has no cut
            survey = os.path.join(cuts, name + "-survey.txt")
            c, w = os.path.join(tmp, name + "-c.csv"), os.path.join(tmp, name + "-w.csv")
            localize(cut, survey, c)
            localize(whole, survey, w)
            C, W = trajectory(c), trajectory(w)
            tv, zv = vicon_height(cut)
            tf = float(C["t"][0])
            vz = (np.interp(tf + 0.1, tv, zv) - np.interp(tf - 0.1, tv, zv)) / 0.2
            z = float(np.interp(tf, tv, zv))
            r = (at(C, tf, "vz") - vz, at(W, tf, "vz") - vz, at(C, tf, "z") - z, at(W, tf, "z") - z,
                 at(W, tf, "acc_bias_z"), at(C, tf + 2, "acc_bias_z"), at(C, tf + 5, "acc_bias_z"),
                 at(W, tf + 5, "acc_bias_z"))
            rows.append(r)
            print(f"{name:12s} {tf:7.2f} {r[0]:+6.2f} {r[1]:+6.2f} {r[2]:+6.2f} {r[3]:+6.2f} {r[4]:+9.3f} "
                  f"{r[5]:+8.3f} {r[6]:+8.3f} {r[7]:+10.3f}")
        if not rows:
            sys.exit("cut_start.py: no cut was written (flights too short for this start?)")
        a = np.array(rows)
        rms = lambda x: float(np.sqrt(np.mean(x ** 2)))
        print(f"RMS over {len(rows)} cuts: vz error cut {rms(a[:, 0]):.2f} / whole {rms(a[:, 1]):.2f} m/s, "
              f"z error cut {rms(a[:, 2]):.2f} / whole {rms(a[:, 3]):.2f} m; |b_z cut - whole| at +5 s, median "
              f"{float(np.median(np.abs(a[:, 6] - a[:, 7]))):.3f} m/s^2")


if __name__ == "__main__":
    main()
