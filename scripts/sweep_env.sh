# Sourced by the sweep scripts (rate_sweep.sh, zero_bias_drift.sh): `source sweep_env.sh NAME BUILD_DIR` sets CLI
# (BUILD_DIR/uwbtdoa; exits 2 with a message naming NAME when it is not built), PY (a Python 3) and WORK (a temporary
# folder, removed when the script exits).
CLI="$2/uwbtdoa"
[ -x "$CLI" ] || { echo "$1: $CLI not found (build first)" >&2; exit 2; }
PY=/usr/bin/python3
[ -x "$PY" ] || PY=python3
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
