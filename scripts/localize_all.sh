#!/usr/bin/env bash
# Runs `uwbtdoa localize` with default parameters on the 16 UTIL pilot TDoA2 flights (IMU-driven ESKF) and the
# 6 util-final-extract flights (no IMU → TDoA-only constant-velocity mode) and prints a table of RMSEs
# (rtf_cpu: flight duration / CPU time of the filter run, including interpolation and metrics).
# Usage: scripts/localize_all.sh [BUILD_DIR] [extra localize flags...]   (data: $UWBTDOA_DATA or ../shared/data)
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD="${1:-build}"
shift || true
CLI="$BUILD/uwbtdoa"
DATA="${UWBTDOA_DATA:-$(cd .. && pwd)/shared/data}"
PILOT="$DATA/real/util-pilot"
EXTRACT="$DATA/real/util-final-extract"
[ -x "$CLI" ] || { echo "no $CLI; build first (cmake --build $BUILD --target uwbtdoa)" >&2; exit 1; }
[ -d "$PILOT" ] || { echo "no data under $PILOT (set UWBTDOA_DATA)" >&2; exit 1; }

TMP="$(mktemp)"
trap 'rm -f "$TMP"' EXIT
runs=()
for i in 1 2 3 4 5 6 7 8 9 10 11 12; do runs+=("$PILOT/0425/0425-traj$i.csv|$PILOT/survey/anchor_0425_survey.txt"); done
for i in 1 2 11 12; do runs+=("$PILOT/0426/0426-traj$i.csv|$PILOT/survey/anchor_0426_survey.txt"); done
for t in trial1 trial2; do for j in 1 2 3; do
  runs+=("$EXTRACT/const4-$t-tdoa2-traj$j.csv|$EXTRACT/survey/anchor_const4_survey.txt")
done; done

printf "%-28s %-5s %8s %8s %7s %7s %7s %7s %7s %8s %8s %7s\n" flight model air_rmse rmse air_x air_y air_z air_p50 air_p90 used rejected rtf_cpu
for r in "${runs[@]}"; do
  f="${r%%|*}"; s="${r##*|}"
  [ -f "$f" ] || { echo "missing $f" >&2; continue; }
  "$CLI" localize "$f" --anchors "$s" --json "$@" | /usr/bin/python3 -c '
import json, sys, os
j = json.load(sys.stdin)
a = j["airborne"]
print("%-28s %-5s %8.3f %8.3f %7.3f %7.3f %7.3f %7.3f %7.3f %8d %8d %7.0f" % (os.path.basename(j["flight"]), j["process_model"],
      j["rmse_airborne_m"], j["rmse_m"], a["rmse_x_m"], a["rmse_y_m"], a["rmse_z_m"], a["p50_m"], a["p90_m"],
      j["n_tdoa_used"], j["n_tdoa_rejected"], j["real_time_factor_cpu"]))'
done > "$TMP"
cat "$TMP"
/usr/bin/python3 -c '
import sys, statistics
rows = [l.split() for l in sys.stdin if l.strip()]
for model in ("imu", "cv"):
    v = [float(r[2]) for r in rows if r[1] == model]
    if v: print("%s flights: %d, airborne RMSE median %.3f m, mean %.3f m, max %.3f m" % (model, len(v), statistics.median(v), statistics.mean(v), max(v)))' < "$TMP"
