#!/usr/bin/env bash
# Sensor sweep: simulated flights with the IMU and the TDoA logged at other rates than the UTIL flights'
# (1 kHz / ~400 Hz), with a quieter accelerometer (0.08 and 0.04 m/s² per sample instead of 0.15: a soft-mounted
# or filtered IMU), with an uncalibrated gyro (turn-on bias 0.03 rad/s per axis instead of 0.0087), and in the TDoA3
# mode (random anchor pairs at 200 Hz instead of the TDoA2 neighbour round robin), localized with the defaults.
# Prints one Markdown row per constellation, trajectory and sensor setting: airborne RMSE and largest error (median
# and worst over the seeds), TDoA used, re-acquisitions.
#
# Usage: scripts/rate_sweep.sh [BUILD_DIR] [SEEDS...]     (default: build, seeds 3 5)
# The util-const presets read their surveys from the data directory ($UWBTDOA_DATA or ../shared/data); without it
# only the built-in `paper` constellation runs.
set -euo pipefail
BUILD=${1:-build}
shift || true
SEEDS=("$@")
[ ${#SEEDS[@]} -gt 0 ] || SEEDS=(3 5)
source "$(dirname "$0")/sweep_env.sh" rate_sweep "$BUILD"

PRESETS=(paper)
if [ -f "$("$CLI" paths)/real/util-final-extract/survey/anchor_const1_survey.txt" ]; then
  PRESETS+=(util-const1 util-const2 util-const3 util-const4)
else
  echo "rate_sweep: no UTIL surveys in the data directory; only the paper constellation" >&2
fi

echo "| anchors | trajectory | IMU [Hz] | TDoA [Hz] | acc noise [m/s²] | gyro bias [rad/s] | pairs | airborne RMSE median / worst [m] | largest error median / worst [m] | TDoA used (min) | re-acquisitions |"
echo "|---|---|---:|---:|---:|---:|---|---|---|---:|---:|"
for preset in "${PRESETS[@]}"; do
  for traj in circle figure8 zigzag hover; do
    for setting in "1000 400 0.15 0.0087 tdoa2" "250 400 0.15 0.0087 tdoa2" "100 400 0.15 0.0087 tdoa2" \
      "1000 100 0.15 0.0087 tdoa2" "100 100 0.15 0.0087 tdoa2" "1000 400 0.08 0.0087 tdoa2" \
      "1000 400 0.04 0.0087 tdoa2" "1000 400 0.15 0.03 tdoa2" "1000 200 0.15 0.0087 tdoa3"; do
      read -r imu tdoa acc gyro mode <<<"$setting"
      tdoa3=false
      [ "$mode" = tdoa3 ] && tdoa3=true
      printf '{"imu": {"rate_hz": %s, "acc_noise_std_mps2": %s, "gyro_bias_std_rps": %s}, "tdoa": {"rate_hz": %s, "tdoa3": %s}}\n' \
        "$imu" "$acc" "$gyro" "$tdoa" "$tdoa3" >"$WORK/cfg.json"
      : >"$WORK/runs.jsonl"
      for seed in "${SEEDS[@]}"; do
        "$CLI" simulate --trajectory "$traj" --duration 40 --seed "$seed" --anchors-preset "$preset" \
          --config "$WORK/cfg.json" --out "$WORK/f.csv" --survey-out "$WORK/s.txt" >/dev/null
        "$CLI" localize "$WORK/f.csv" --anchors "$WORK/s.txt" --json --no-diagnostics 2>/dev/null >>"$WORK/runs.jsonl"
        echo >>"$WORK/runs.jsonl"
      done
      "$PY" - "$WORK/runs.jsonl" "$preset" "$traj" "$imu" "$tdoa" "$acc" "$gyro" "$mode" <<'EOF'
import json, statistics, sys
path, preset, traj, imu, tdoa, acc, gyro, mode = sys.argv[1:]
runs = [json.loads(line) for line in open(path) if line.strip()]
rmse = [r["airborne"]["rmse_m"] for r in runs]
mx = [r["airborne"]["max_m"] for r in runs]
used = min(r["n_tdoa_used"] / r["n_tdoa"] for r in runs)
reacq = sum(r["n_reacquisitions"] for r in runs)
print(f"| {preset} | {traj} | {imu} | {tdoa} | {acc} | {gyro} | {mode.upper().replace('TDOA', 'TDoA')} | {statistics.median(rmse):.3f} / {max(rmse):.3f} | "
      f"{statistics.median(mx):.2f} / {max(mx):.2f} | {100 * used:.0f} % | {reacq} |")
EOF
    done
  done
done
