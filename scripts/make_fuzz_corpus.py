#!/usr/bin/env python3
"""Seed corpora of the fuzz harnesses (fuzz/, scripts/fuzz.sh): small cut-down copies of real UTIL files.

    scripts/make_fuzz_corpus.py OUT_DIR [DATA_DIR]      (DATA_DIR: $UWBTDOA_DATA or ../shared/data)

Writes OUT_DIR/<harness>/seed_* : the first rows of a few real flights (full 27-column layout, position-only
extract, a TWR-free subset), uSD-card event logs of the same rows, surveys, a trajectory CSV derived from a flight's ground truth, bias-model JSON and
config JSON. Without the real data it writes the same kinds of files from built-in rows.
"""
import json
import math
import os
import struct
import sys
import zlib
from pathlib import Path

out = Path(sys.argv[1])
data = Path(sys.argv[2] if len(sys.argv) > 2 else os.environ.get("UWBTDOA_DATA", Path(__file__).resolve().parents[1] / ".." / "shared" / "data"))
real = data / "real"

FALLBACK_FLIGHT = """t_tdoa,idA,idB,tdoa_meas,t_acc,acc_x,acc_y,acc_z,t_gyro,gyro_x,gyro_y,gyro_z,t_tof,tof,t_flow,deltaX,deltaY,t_baro,baro,t_pose,pose_x,pose_y,pose_z,pose_qx,pose_qy,pose_qz,pose_qw
0.005383,7,1,-1.91424,0.000000,-0.002647779,0.004686676,1.000256,0.000017,-0.04690039,-0.1693154,0.007582872,0.018830,0.015,1.178125,-1,0,0.000036,181.1233,0.000496,1.498,0.038,0.03,-0.006918853,-0,-0.03044295,0.9995126
0.007873,1,3,-1.309002,0.000935,-0.002654601,0.004758866,1.000237,0.000959,-0.01746717,-0.1386006,-0.003362787,0.060879,0.017,1.188106,1,4,0.000979,181.1233,0.003314,1.498,0.038,0.03,-0.008302623,-0.001383771,-0.02905918,0.9995422
"""
FALLBACK_SURVEY = """an0_p,-3.04,-4.04,0.21
an1_p,-3.23,3.76,2.95
an2_p,3.69,3.71,0.17
an3_p,4.10,-4.27,3.20
an0_quat,0.66,0.25,0.66,-0.26
"""


def head(path, rows):
    """The header and the first `rows` data lines of a text file."""
    lines = []
    with open(path, newline="") as f:
        for i, line in enumerate(f):
            if i > rows:
                break
            lines.append(line)
    return "".join(lines)


def put(harness, name, text):
    d = out / harness
    d.mkdir(parents=True, exist_ok=True)
    (d / name).write_text(text)


flights = []
pilot = real / "util-pilot" / "0425" / "0425-traj2.csv"
extract = real / "util-final-extract" / "const4-trial1-tdoa2-traj1.csv"
if pilot.is_file():
    flights.append(("pilot", head(pilot, 12)))
if extract.is_file():
    flights.append(("extract", head(extract, 8)))
if not flights:
    flights.append(("builtin", FALLBACK_FLIGHT))
for tag, text in flights:
    put("flight_csv", f"seed_{tag}.csv", text)
    put("flight_csv", f"seed_{tag}_short.csv", "".join(text.splitlines(True)[:3]))
# A stream subset: TDoA and pose only, from the full layout (columns picked by name).
lines = flights[0][1].splitlines()
names = lines[0].split(",")
keep = [i for i, n in enumerate(names) if n in ("t_tdoa", "idA", "idB", "tdoa_meas", "t_pose", "pose_x", "pose_y", "pose_z")]
put("flight_csv", "seed_subset.csv", "\n".join(",".join(l.split(",")[i] for i in keep) for l in lines) + "\n")

# uSD-card event logs (cfusdlog, docs/io.md §6) holding the same rows as UTIL recorded them.
def usd_log(rows, version):
    """A cfusdlog file (header, events in row order, CRC-32) with UTIL's event types and field names."""
    types = [(1, "estTDOA", ["idA(B)", "idB(B)", "distanceDiff(f)"], ["t_tdoa", "idA", "idB", "tdoa_meas"]),
             (2, "estAcceleration", ["acc.x(f)", "acc.y(f)", "acc.z(f)"], ["t_acc", "acc_x", "acc_y", "acc_z"]),
             (3, "estGyroscope", ["gyro.x(f)", "gyro.y(f)", "gyro.z(f)"], ["t_gyro", "gyro_x", "gyro_y", "gyro_z"]),
             (4, "estTOF", ["range.zrange(H)"], ["t_tof", "tof"]),
             (5, "estFlow", ["motion.deltaX(h)", "motion.deltaY(h)"], ["t_flow", "deltaX", "deltaY"]),
             (6, "estBarometer", ["baro.asl(f)"], ["t_baro", "baro"]),
             (7, "estPose", ["locSrv.x(f)", "locSrv.y(f)", "locSrv.z(f)", "locSrv.qx(f)", "locSrv.qy(f)",
                             "locSrv.qz(f)", "locSrv.qw(f)"],
              ["t_pose", "pose_x", "pose_y", "pose_z", "pose_qx", "pose_qy", "pose_qz", "pose_qw"])]
    col = {n: i for i, n in enumerate(rows[0].split(","))}
    out = bytearray(struct.pack("<BHH", 0xBC, version, len(types)))
    for tid, name, fields, _ in types:
        out += struct.pack("<H", tid) + name.encode() + b"\0" + struct.pack("<H", len(fields))
        for f in fields:
            out += f.encode() + b"\0"
    events = []
    for line in rows[1:]:
        c = line.split(",")
        for tid, _, fields, cols in types:
            if any(k not in col or c[col[k]].strip() == "" for k in cols):
                continue
            vals = [float(c[col[k]]) for k in cols[1:]]
            fmt = "<" + "".join(f[-2] for f in fields)
            if tid == 4:
                vals = [round(vals[0] * 1000)]
            vals = [int(v) if ch in "BbHhIi" else v for v, ch in zip(vals, fmt[1:])]
            t_us = round(float(c[col[cols[0]]]) * 1e6)
            events.append((t_us, tid, struct.pack(fmt, *vals)))
    events.sort(key=lambda e: (e[0], e[1]))
    for t_us, tid, payload in events:
        stamp = struct.pack("<I", t_us // 1000) if version == 1 else struct.pack("<Q", t_us)
        out += struct.pack("<H", tid) + stamp + payload
    return bytes(out + struct.pack("<I", zlib.crc32(bytes(out)) & 0xFFFFFFFF))


def put_bytes(harness, name, data):
    d = out / harness
    d.mkdir(parents=True, exist_ok=True)
    (d / name).write_bytes(data)


flight_rows = flights[0][1].splitlines()
put_bytes("usd_log", "seed_v2.log", usd_log(flight_rows[:6], 2))
put_bytes("usd_log", "seed_v1.log", usd_log(flight_rows[:4], 1))
put_bytes("usd_log", "seed_cut.log", usd_log(flight_rows[:3], 2)[:-7])

surveys = [real / "util-pilot" / "survey" / "anchor_0425_survey.txt",
           real / "util-final-extract" / "survey" / "anchor_const4_survey.txt"]
found = [s for s in surveys if s.is_file()]
for s in found:
    text = s.read_text()
    put("survey", "seed_" + s.stem + ".txt", text)
    put("survey", "seed_" + s.stem + "_positions.txt", "".join(l for l in text.splitlines(True) if "_p," in l)[:400])
if not found:
    put("survey", "seed_builtin.txt", FALLBACK_SURVEY)

# Trajectory CSV (the `localize --out` layout) from the first rows' ground-truth pose.
traj = ["t,x,y,z,qx,qy,qz,qw,std_x,std_y,std_z,vx,vy,vz"]
idx = {n: i for i, n in enumerate(names)}
if "t_pose" in idx:
    for l in lines[1:6]:
        c = l.split(",")
        q = [c[idx[k]] if k in idx else ("1" if k == "pose_qw" else "0") for k in ("pose_qx", "pose_qy", "pose_qz", "pose_qw")]
        traj.append(",".join([c[idx["t_pose"]], c[idx["pose_x"]], c[idx["pose_y"]], c[idx["pose_z"]], *q,
                              "0.05", "0.05", "0.08", "0", "0", "0"]))
put("trajectory_csv", "seed_traj.csv", "\n".join(traj) + "\n")
# the same with the IMU-driven filter's bias columns
bias_cols = ",acc_bias_x,acc_bias_y,acc_bias_z,gyro_bias_x,gyro_bias_y,gyro_bias_z"
put("trajectory_csv", "seed_traj_bias.csv",
    "\n".join([traj[0] + bias_cols] + [r + ",0.01,-0.02,-0.108,0.001,0,-0.0004" for r in traj[1:]]) + "\n")


def svgp(m_points, dims, l):
    """A small SVGP block in the layout of gp::Svgp::toJson (identity q(u) factor, ARD squared exponential)."""
    Z = [[round(math.sin(1.3 * i + k), 4) for k in range(dims)] for i in range(m_points)]
    L = [[1.0 if r == c else 0.0 for c in range(m_points)] for r in range(m_points)]
    return {"format": "uwbtdoa-svgp", "version": 1,
            "kernel": {"combination": "sum_of_products", "terms": [[0]], "fixed": [], "name": "se",
                       "parts": [{"type": "se", "active_dims": list(range(dims)), "sigma2": 0.01, "l": [l] * dims}]},
            "inducing_points": Z, "variational": {"m": [0.01 * i for i in range(m_points)], "L": L},
            "mean": {"type": "constant", "constant": 0.0}, "likelihood": {"type": "gaussian", "noise": 0.01},
            "jitter": 1e-6, "input_transform": {"shift": [0.0] * dims, "scale": [1.0] * dims}}


model_global = {"format": "uwbtdoa-bias-model", "version": 1, "preset": "tdoa", "features": "body_positions",
                "feature_columns": 6, "per_pair": False,
                "models": [{"id_a": -1, "id_b": -1, "svgp": svgp(3, 6, 1.0)}], "pair_means": [],
                "extra_variance_m2": 0.0, "training": {"inputs": "estimate"}}
put("bias_model", "seed_global.json", json.dumps(model_global, indent=1))
model_pairs = dict(model_global, preset="pair-tdoa", per_pair=True,
                   models=[{"id_a": 0, "id_b": 1, "svgp": svgp(2, 6, 0.5)}, {"id_a": 1, "id_b": 2, "svgp": svgp(2, 6, 2.0)}],
                   pair_means=[{"id_a": 0, "id_b": 1, "mean_m": 0.05}])
put("bias_model", "seed_pairs.json", json.dumps(model_pairs))

put("config_json", "seed_localize.json", json.dumps({"tdoa_sigma_m": 0.1, "robust_loss": "cauchy", "robust_iterations": 2,
                                                     "b_t_tag": [0, 0, 0.03], "fuse_tof": True, "process_model": "imu"}))
put("config_json", "seed_localize_start.json", json.dumps({"start_w_p_b": [1.5, 0.0, 0.1], "ground_phase": "detect"}))
put("config_json", "seed_simulate.json", json.dumps({"bias": {"enabled": True, "multipath_features": 8, "noise_std_m": 0.05},
                                                     "trajectory": {"radius_m": 1.0}, "imu": {"rate_hz": 500.0},
                                                     "b_t_tag": [0, 0, 0.02]}))

# the stream's line protocol: a short synthetic flight at rest (IMU at 100 Hz, TDoA between the harness's 8 anchors),
# the same with one stamp far ahead, and with a clock that restarts at 0 (a reboot)
def stream_lines(t0, n, rebase_at=None, outlier_at=None):
    lines = ["# uwbtdoa-events v1"]
    for i in range(n):
        t = t0 + 0.01 * i
        if rebase_at is not None and i >= rebase_at:
            t = 0.01 * (i - rebase_at)
        if outlier_at == i:
            t = 1e12
        lines.append(f"imu,{t:.3f},0.01,-0.02,9.81,0.001,-0.002,0.0005")
        if i % 2 == 0:
            a, b = i % 8, (i + 3) % 8
            lines.append(f"tdoa,{t + 0.004:.3f},{a},{b},{0.1 * ((i * 7) % 11) - 0.5:.3f}")
        if i % 10 == 0:
            lines.append(f"tof,{t + 0.006:.3f},0.03")
    return "\n".join(lines) + "\n"


put("stream_line", "seed_rest.txt", stream_lines(0.0, 60))
put("stream_line", "seed_outlier.txt", stream_lines(20.0, 40, outlier_at=12))
put("stream_line", "seed_reboot.txt", stream_lines(20.0, 40, rebase_at=20))
put("stream_line", "seed_bad.txt", "imu,1,2\ntdoa,0.5,3,3,0.1\ntdoa,0.6,-1,300,0.2\nzzz\ntof,1e400,1\n")

# JSON deep and wide (fuzz_json_deep with -max_len=300000): nesting of 100 000 levels, wide arrays and objects
put("json_deep", "seed_deep_array.json", "[" * 100000 + "]" * 100000)
put("json_deep", "seed_deep_object.json", '{"a":' * 40000 + "1" + "}" * 40000)
put("json_deep", "seed_deep_config.json", '{"tdoa_sigma_m":' + "[" * 50000 + "]" * 50000 + "}")
put("json_deep", "seed_wide_array.json", "[" + ",".join(["0.5"] * 60000) + "]")
put("json_deep", "seed_wide_object.json", "{" + ",".join(f'"k{i}":{i}' for i in range(20000)) + "}")
put("json_deep", "seed_config.json", json.dumps({"tdoa_sigma_m": 0.1, "robust_loss": "cauchy", "b_t_tag": [0, 0, 0.03]}))
print(f"seed corpora written to {out}")
