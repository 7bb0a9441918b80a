#!/usr/bin/env python3
"""Coverage of the reported σ while the body sits on the floor (docs/math/filter.md F23), on the util-pilot flights.

    scripts/ground_coverage.py [BUILD_DIR] [-- extra localize flags]       (BUILD_DIR: build)

For each development flight (0425: traj1–12, 0426: traj1, 2, 11, 12): `uwbtdoa localize FLIGHT --anchors SURVEY --json
--no-diagnostics --out TRAJ --output-period 0.05`. Samples on the floor: before the reported take-off, or from 1 s after
the reported landing on, with ground-truth z < 0.3 m. Per flight and axis: the fraction of those samples whose error
|p̂ − p| lies within 1σ and 2σ of the reported std, and the RMS error; printed as the median over the session's
flights. Needs the Python module (BUILD_DIR/python) and the data directory (`uwbtdoa paths`).
"""
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from script_args import pilot_setup

args = sys.argv[1:]
extra = args[args.index("--") + 1:] if "--" in args else []
args = args[: args.index("--")] if "--" in args else args
uwbtdoa, cli, pilot = pilot_setup(args[0] if args else "build")

sessions = {"0425": [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12], "0426": [1, 2, 11, 12]}
print("| session | part | flights | 1σ coverage x/y/z [%] | 2σ coverage x/y/z [%] | RMS error x/y/z [m] | median σ x/y/z [m] |")
print("|---|---|---:|---|---|---|---|")
with tempfile.TemporaryDirectory() as tmp:
    traj_path = str(Path(tmp) / "traj.csv")
    for session, numbers in sessions.items():
        per_part = {"before take-off": [], "after landing": []}
        for k in numbers:
            flight = pilot / session / f"{session}-traj{k}.csv"
            run = subprocess.run([cli, "localize", str(flight), "--anchors", str(pilot / "survey" / f"anchor_{session}_survey.txt"),
                                  "--json", "--no-diagnostics", "--out", traj_path, "--output-period", "0.05", *extra],
                                 capture_output=True, text=True, check=True)
            summary = json.loads(run.stdout)
            traj = uwbtdoa.read_trajectory_csv(traj_path)
            pose = uwbtdoa.read_flight_csv(str(flight)).pose
            t, p, sd = np.asarray(traj["t"]), np.asarray(traj["p"]), np.asarray(traj["sigma_p"])
            truth = np.column_stack([np.interp(t, pose["t"], pose["p"][:, i]) for i in range(3)])
            low = truth[:, 2] < 0.3
            parts = {"before take-off": low & (t < (summary.get("takeoff_t_s") or -np.inf))}
            if summary.get("landing_t_s") is not None:
                parts["after landing"] = low & (t > summary["landing_t_s"] + 1.0)
            for name, m in parts.items():
                if m.sum() < 5:
                    continue
                e = np.abs(p[m] - truth[m])
                per_part[name].append((np.mean(e < sd[m], axis=0), np.mean(e < 2 * sd[m], axis=0),
                                       np.sqrt(np.mean(e**2, axis=0)), np.median(sd[m], axis=0)))
        for name, rows in per_part.items():
            if not rows:
                continue
            med = [np.median([r[i] for r in rows], axis=0) for i in range(4)]
            print(f"| {session} | {name} | {len(rows)} | {'/'.join(f'{100 * v:.0f}' for v in med[0])} | "
                  f"{'/'.join(f'{100 * v:.0f}' for v in med[1])} | {'/'.join(f'{v:.2f}' for v in med[2])} | "
                  f"{'/'.join(f'{v:.2f}' for v in med[3])} |")
