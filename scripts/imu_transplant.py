#!/usr/bin/python3
"""Gives a real flight another drone's IMU signature (docs/math/simulation.md S24, the transplants of the
sensor-signature matrix): rotor vibration in flight, a quiet or idling floor.

    scripts/imu_transplant.py IN.csv OUT.csv [--gyro-vib DEG_S] [--acc-vib G] [--floor off|idle|keep]
                              [--floor-gyro DEG_S] [--seed N]

The flight's own IMU is first low-passed (a centred moving mean over --smooth-ms, which keeps manoeuvres and drops
the rotor band), then, where the Vicon height is more than --air-height above its floor level, vibration tones at
150-240 Hz (three per axis, random phases, amplitudes scaled to the RMS asked for) plus broadband noise of a
quarter of that RMS are added; on the floor (at or below the floor level + --air-height) the IMU becomes the low-passed
signal plus white noise of the motors-off level (--floor off), or plus idle vibration of --floor-gyro RMS (--floor
idle). The TDoA, pose and other columns are copied unchanged.
"""
import argparse
import csv
import math
import os
import sys
import tempfile

import numpy as np

G = 9.81


def column(rows, header, name):
    i = header.index(name)
    vals = []
    for r in rows:
        if i < len(r) and r[i] != "":
            vals.append(float(r[i]))
        else:
            break
    return np.array(vals)


def smooth(x, n):
    if n <= 1:
        return x.copy()
    k = np.ones(n) / n
    pad = n // 2
    xp = np.concatenate([np.full(pad, x[0]), x, np.full(n - 1 - pad, x[-1])])
    return np.convolve(xp, k, mode="valid")


def tones(t, rms, rng):
    """Three tones per axis at 150-240 Hz with random phases, total RMS `rms`, plus broadband noise rms/4."""
    out = np.zeros((len(t), 3))
    for ax in range(3):
        f = rng.uniform(150.0, 240.0, 3)
        ph = rng.uniform(0, 2 * math.pi, 3)
        s = sum(np.sin(2 * math.pi * fi * t + p) for fi, p in zip(f, ph))
        s *= rms / math.sqrt(3) / np.sqrt(np.mean(s ** 2) + 1e-30)
        out[:, ax] = s + rng.normal(0.0, rms / 4.0 / math.sqrt(3), len(t))
    return out * math.sqrt(16.0 / 17.0)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("inp")
    ap.add_argument("out")
    ap.add_argument("--gyro-vib", type=float, default=20.0, help="in-flight gyro vibration RMS [deg/s] (norm)")
    ap.add_argument("--acc-vib", type=float, default=0.005, help="in-flight accelerometer vibration RMS [g] (norm)")
    ap.add_argument("--floor", choices=["off", "idle", "keep"], default="off")
    ap.add_argument("--floor-gyro", type=float, default=20.0, help="idle gyro vibration on the floor [deg/s]")
    ap.add_argument("--air-height", type=float, default=0.15, help="airborne above the floor level + this [m]")
    ap.add_argument("--smooth-ms", type=float, default=10.0)
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    rng = np.random.default_rng(a.seed)

    with open(a.inp, newline="") as f:
        rd = csv.reader(f)
        header = next(rd)
        rows = [r for r in rd]
    t_acc = column(rows, header, "t_acc")
    t_gyro = column(rows, header, "t_gyro")
    t_pose = column(rows, header, "t_pose")
    pz = column(rows, header, "pose_z")
    floor = np.percentile(pz, 2)
    acc = np.stack([column(rows, header, c) for c in ("acc_x", "acc_y", "acc_z")], 1)
    gyro = np.stack([column(rows, header, c) for c in ("gyro_x", "gyro_y", "gyro_z")], 1)

    def airborne(t):
        return np.interp(t, t_pose, pz) > floor + a.air_height

    for name, tt, x, vib, unit in (("acc", t_acc, acc, a.acc_vib, 1.0), ("gyro", t_gyro, gyro, a.gyro_vib, 1.0)):
        dt = np.median(np.diff(tt))
        n = max(1, int(round(a.smooth_ms * 1e-3 / dt)))
        low = np.stack([smooth(x[:, k], n) for k in range(3)], 1)
        air = airborne(tt)
        new = low.copy()
        new[air] += tones(tt[air], vib, rng)
        ground = ~air
        if a.floor == "keep":
            new[ground] = x[ground]
        elif a.floor == "idle":
            fv = a.floor_gyro if name == "gyro" else 0.05
            new[ground] += tones(tt[ground], fv, rng)
        else:
            quiet = 0.003 if name == "acc" else 0.2  # [g], [deg/s] motors off
            new[ground] += rng.normal(0.0, quiet / math.sqrt(3), (ground.sum(), 3))
        cols = [header.index(c) for c in ((f"{name}_x", f"{name}_y", f"{name}_z"))]
        for i in range(len(tt)):
            for k, c in enumerate(cols):
                rows[i][c] = "%.7g" % new[i, k]

    d = os.path.dirname(os.path.abspath(a.out))
    fd, tmp = tempfile.mkstemp(dir=d, prefix=".transplant-")
    try:
        with os.fdopen(fd, "w", newline="") as f:
            w = csv.writer(f, lineterminator="\n")
            w.writerow(header)
            w.writerows(rows)
        os.chmod(tmp, 0o644)
        os.replace(tmp, a.out)
    except BaseException:
        os.unlink(tmp)
        raise


if __name__ == "__main__":
    sys.exit(main())
