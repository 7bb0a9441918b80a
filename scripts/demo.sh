#!/usr/bin/env bash
# README command 1: installs the missing Debian packages, builds only the `uwbtdoa` program (no tests, benchmarks or
# Python module; no compiler warnings: those belong to the developer build of scripts/test.sh) and runs the
# built-in demo. Progress lines say what is happening and about how long is left.
set -euo pipefail
cd "$(dirname "$0")/.."
start=$(date +%s)
UWB_TARGETS=uwbtdoa UWB_QUIET=1 scripts/setup.sh -DUWB_DEV_WARNINGS=OFF
echo "[demo] uwbtdoa built in $(( $(date +%s) - start )) s; running the demo (about half a minute on two cores)"
exec build/uwbtdoa demo "$@"
