#!/usr/bin/env bash
# Does learning the range biases online (docs/math/filter.md F27) cost anything on a flight without bias? Simulated
# flights whose TDoA carry white noise only (every bias term of S12-S18 off, no outliers, no ground effect), four
# trajectories x three seeds x two constellations, 120 s each, localized with the defaults ("on"), without the
# range-bias states at the same white-noise std ("off 0.2"), and without them at the std of the filter without the
# states ("off 0.35"). Prints one row per flight and the median and range of the change on / off.
#
# Usage: scripts/zero_bias_drift.sh [BUILD_DIR] [FLAGS...]   (FLAGS: added to the "on" run, e.g. filter parameters)
set -euo pipefail
BUILD=${1:-build}
shift || true
ON_FLAGS=("$@")
source "$(dirname "$0")/sweep_env.sh" zero_bias_drift "$BUILD"
cat > "$WORK/cfg.json" <<'JSON'
{"bias": {"antenna_rms_m": 0, "anchor_pattern_rms_m": 0, "anchor_offset_std_m": 0, "nlos_bias_m": 0,
          "multipath_std_m": 0, "outlier_probability": 0, "burst_probability": 0, "ground_effect": false}}
JSON
rmse() { "$CLI" localize "$1" --anchors "$2" --json --no-diagnostics "${@:3}" |
  "$PY" -c 'import json, sys; print("%.5f" % json.load(sys.stdin)["rmse_airborne_m"])'; }
echo "| flight | on [m] | off 0.2 [m] | off 0.35 [m] |"
echo "|---|---:|---:|---:|"
for tr in circle figure8 zigzag circle-sine; do
  for seed in 1 2 3; do
    for anchors in paper util-pilot-0425; do
      n="$tr-s$seed-$anchors"
      "$CLI" simulate --trajectory "$tr" --seed "$seed" --anchors-preset "$anchors" --duration 120 \
        --config "$WORK/cfg.json" --out "$WORK/$n.csv" --survey-out "$WORK/$n.txt" > /dev/null
      on=$(rmse "$WORK/$n.csv" "$WORK/$n.txt" "${ON_FLAGS[@]}")
      off=$(rmse "$WORK/$n.csv" "$WORK/$n.txt" --range-bias-sigma-m 0)
      off35=$(rmse "$WORK/$n.csv" "$WORK/$n.txt" --range-bias-sigma-m 0 --tdoa-sigma-m 0.35)
      echo "| $n | $on | $off | $off35 |" | tee -a "$WORK/rows"
    done
  done
done
"$PY" - "$WORK/rows" <<'PYEOF'
import statistics, sys
rows = [[float(c) for c in l.split("|")[2:5]] for l in open(sys.argv[1])]
for k, name in ((1, "off 0.2"), (2, "off 0.35")):
    ch = [100 * (r[0] / r[k] - 1) for r in rows]
    print(f"on vs {name}: median {statistics.median(ch):+.1f} %, range {min(ch):+.1f} … {max(ch):+.1f} % "
          f"(n = {len(ch)})")
PYEOF
