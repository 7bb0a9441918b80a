#!/usr/bin/env bash
# Bias-RMSE table of the TDoA bias GP (docs/results.md): for each kernel and number of inducing points,
# train on one set of real flights and apply the model to other flights. The GP inputs come from INPUTS: 'estimate'
# (default: the uncorrected filter's pose, as at run time) or 'truth' (ground-truth pose); predict-bias uses the same.
#
#   scripts/train_all.sh [OUT_DIR]            env: UWBTDOA (CLI), DATA, EPOCHS, KERNELS, INDUCING, SEED, INPUTS
#
# Splits (util-pilot SOURCE.md): 0425-traj6..9 -> 0425-traj1..4, and 0426-traj11 -> 0426-traj12.
# Test metric: bias RMSE over the airborne test samples (gt z > 0.3 m, |eps| <= 1 m), before (raw eps) and after
# (eps - GP mean), pooled over the test flights. Writes OUT_DIR/bias_table.{md,csv} and the per-run JSON.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
OUT="${1:-$ROOT/build/gp-results}"
UWBTDOA="${UWBTDOA:-$ROOT/build/uwbtdoa}"
DATA="${DATA:-$ROOT/../shared/data/real/util-pilot}"
EPOCHS="${EPOCHS:-15}"
SEED="${SEED:-1}"
INPUTS="${INPUTS:-estimate}"
KERNELS="${KERNELS:-z1 z2 tdoa pair-tdoa pair-pos pair-tdoa-pos}"
INDUCING="${INDUCING:-10 30 50 100 170}"
mkdir -p "$OUT"
[[ -x "$UWBTDOA" ]] || { echo "uwbtdoa not found at $UWBTDOA (build it or set UWBTDOA)" >&2; exit 1; }

declare -A TRAIN TEST SURVEY
TRAIN[0425]="0425/0425-traj6.csv 0425/0425-traj7.csv 0425/0425-traj8.csv 0425/0425-traj9.csv"
TEST[0425]="0425/0425-traj1.csv 0425/0425-traj2.csv 0425/0425-traj3.csv 0425/0425-traj4.csv"
SURVEY[0425]="survey/anchor_0425_survey.txt"
TRAIN[0426]="0426/0426-traj11.csv"
TEST[0426]="0426/0426-traj12.csv"
SURVEY[0426]="survey/anchor_0426_survey.txt"

for split in 0425 0426; do
  train_files=(); for f in ${TRAIN[$split]}; do train_files+=("$DATA/$f"); done
  for k in $KERNELS; do
    for m in $INDUCING; do
      tag="${split}_${k}_M${m}"
      echo ">> $tag" >&2
      "$UWBTDOA" train "${train_files[@]}" --anchors "$DATA/${SURVEY[$split]}" --kernel "$k" --inducing "$m" \
        --epochs "$EPOCHS" --seed "$SEED" --inputs "$INPUTS" --out "$OUT/$tag.model.json" --json --quiet > "$OUT/$tag.train.json"
      : > "$OUT/$tag.test.jsonl"
      for f in ${TEST[$split]}; do
        "$UWBTDOA" predict-bias "$DATA/$f" --anchors "$DATA/${SURVEY[$split]}" --model "$OUT/$tag.model.json" \
          --out "$OUT/$tag.$(basename "$f" .csv).bias.csv" --json >> "$OUT/$tag.test.jsonl"
      done
    done
  done
done

python3 - "$OUT" "$KERNELS" "$INDUCING" <<'EOF'
import json, math, sys, os
out, kernels, inducing = sys.argv[1], sys.argv[2].split(), [int(m) for m in sys.argv[3].split()]
names = {"0425": "0425-traj6..9 -> 0425-traj1..4", "0426": "0426-traj11 -> 0426-traj12"}
rows = []
for split in ("0425", "0426"):
    for k in kernels:
        for m in inducing:
            tag = f"{split}_{k}_M{m}"
            tr = json.load(open(f"{out}/{tag}.train.json"))
            n = sb = sa = 0.0
            for line in open(f"{out}/{tag}.test.jsonl"):
                t = json.loads(line)
                n += t["n_airborne"]; sb += t["n_airborne"] * t["bias_rmse_before_m"] ** 2
                sa += t["n_airborne"] * t["bias_rmse_after_m"] ** 2
            before, after = math.sqrt(sb / n), math.sqrt(sa / n)
            rows.append(dict(split=names[split], kernel=k, inducing=m, n_train=tr["n_train"], n_test=int(n),
                             holdout_before_m=tr["bias_rmse_before_m"], holdout_after_m=tr["bias_rmse_after_m"],
                             test_before_m=before, test_after_m=after, change_pct=100 * (after - before) / before,
                             train_seconds=tr["train_seconds"]))
with open(f"{out}/bias_table.csv", "w") as f:
    f.write(",".join(rows[0].keys()) + "\n")
    for r in rows: f.write(",".join(str(v) for v in r.values()) + "\n")
with open(f"{out}/bias_table.md", "w") as f:
    f.write("| split | kernel | M | n_train | n_test | test bias RMSE before [m] | after [m] | change | held-out (train flights) before → after [m] | train s |\n")
    f.write("|---|---|---|---|---|---|---|---|---|---|\n")
    for r in rows:
        f.write(f"| {r['split']} | {r['kernel']} | {r['inducing']} | {r['n_train']} | {r['n_test']} | {r['test_before_m']:.4f} | "
                f"{r['test_after_m']:.4f} | {r['change_pct']:+.1f} % | {r['holdout_before_m']:.4f} → {r['holdout_after_m']:.4f} | {r['train_seconds']:.1f} |\n")
print(open(f"{out}/bias_table.md").read())
EOF
