#!/usr/bin/env bash
# Builds the libFuzzer harnesses (fuzz/, clang 14, ASan + UBSan) into build-fuzz/ and runs each in turn.
#
#   scripts/fuzz.sh [SECONDS_PER_HARNESS] [HARNESS...]     (default: 60 s each; harnesses: flight_csv usd_log survey
#                                                          trajectory_csv bias_model config_json stream_line json_deep)
#
# Seed corpora: scripts/make_fuzz_corpus.py cuts a few rows out of the real files (build-fuzz/seeds/<harness>);
# the growing corpus lives in build-fuzz/corpus/<harness>. A crash stops that harness and leaves its input in
# build-fuzz/crashes/<harness>/; turn it into a regression test (docs/robustness.md) once fixed.
# Runs niced (nice -n 15) with one job: the harnesses share the machine.
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_EACH="${1:-60}"
shift || true
HARNESSES=("$@")
((${#HARNESSES[@]})) || HARNESSES=(flight_csv usd_log survey trajectory_csv bias_model config_json stream_line json_deep)
BUILD=build-fuzz

command -v clang++-14 >/dev/null || UWB_WITH_CLANG=1 UWB_PACKAGES_ONLY=1 scripts/setup.sh
command -v clang++-14 >/dev/null || { echo "[fuzz] clang++-14 not found (apt-get install clang-14 libclang-rt-14-dev)" >&2; exit 1; }
if [ ! -f "$BUILD/CMakeCache.txt" ]; then
  echo "[fuzz] configuring $BUILD (clang 14, -DUWB_FUZZ=ON)"
  CC=clang-14 CXX=clang++-14 cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DUWB_FUZZ=ON \
    -DUWB_BUILD_TESTS=OFF -DUWB_BUILD_BENCHMARKS=OFF -DUWB_BUILD_PYTHON=OFF -DUWB_NATIVE=OFF >/dev/null
fi
echo "[fuzz] building the harnesses"
nice -n 15 cmake --build "$BUILD" -j "${UWB_JOBS:-2}" --target fuzzers
/usr/bin/python3 scripts/make_fuzz_corpus.py "$BUILD/seeds" >/dev/null

status=0
for h in "${HARNESSES[@]}"; do
  mkdir -p "$BUILD/corpus/$h" "$BUILD/crashes/$h"
  echo "[fuzz] $h for $SECONDS_EACH s"
  # -rss_limit_mb / -malloc_limit_mb: a reader that allocates gigabytes for a small input is a finding too.
  # json_deep reads up to 300 000 bytes: nesting of 100 000 levels (a recursive reader's stack overflow)
  max_len=65536
  [ "$h" = json_deep ] && max_len=300000
  if ! UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 ASAN_OPTIONS=detect_leaks=1 \
      nice -n 15 "$BUILD/fuzz/fuzz_$h" "$BUILD/corpus/$h" "$BUILD/seeds/$h" -max_total_time="$SECONDS_EACH" \
      -rss_limit_mb=2048 -malloc_limit_mb=1024 -max_len="$max_len" -timeout=10 -print_final_stats=1 \
      -artifact_prefix="$BUILD/crashes/$h/" > "$BUILD/fuzz_$h.log" 2>&1; then
    echo "[fuzz] $h: FOUND A PROBLEM, see $BUILD/fuzz_$h.log and $BUILD/crashes/$h/" >&2
    status=1
  fi
  grep -E "^stat::(number_of_executed_units|peak_rss_mb)|cov: " "$BUILD/fuzz_$h.log" | tail -3 | sed "s/^/[fuzz] $h: /"
done
exit $status
