#!/usr/bin/env bash
# README command 2: install, build everything (Release and ASan+UBSan), run the whole test suite (ctest + pytest),
# the CLI tests included under the sanitizers.
# Suites named Slow* (Monte-Carlo, long real-data evaluations) run with: ctest --test-dir build -R "^Slow".
# UWB_SKIP_SANITIZE=1 skips the sanitizer build (for quick local iterations only; CI always runs it).
set -euo pipefail
cd "$(dirname "$0")/.."
# Every build step's output also goes to a log. A compiler warning in the project's own code fails the run; a warning
# that arises inside a third-party or system header (a path under /usr: GCC's false positives in Eigen's and its own
# intrinsics headers, which depend on the CPU under -march=native) is shown but does not fail it, so that another
# machine's CPU cannot turn the run red on a header that is not ours (the known ones are silenced in
# cmake/UwbHelpers.cmake). Developers: -DUWB_WERROR=ON makes every warning of the project's targets an error.
BUILD_LOG="$(mktemp)"
trap 'rm -f "$BUILD_LOG"' EXIT
no_warnings() {
  local all own
  all=$(grep -c "warning:" "$BUILD_LOG" || true)
  own=$(grep "warning:" "$BUILD_LOG" | grep -c -v "^/usr/" || true)
  if [ "$all" != "0" ]; then
    grep "warning:" "$BUILD_LOG" | head -20 >&2
    echo "[test] $all compiler warning line(s) in the $1 build, $own in the project's own code (first 20 above)" >&2
  fi
  if [ "$own" != "0" ]; then
    echo "[test] failed: fix the warnings in the project's own code" >&2
    exit 1
  fi
}
scripts/setup.sh 2>&1 | tee "$BUILD_LOG"
no_warnings Release
JOBS="${UWB_JOBS:-$(nproc)}"

echo "[test] unit and regression tests (Release)"
ctest --test-dir build --output-on-failure -j "$JOBS" -LE slow -E "^Slow"

echo "[test] Python tests"
PYTHONPATH="$PWD/build/python" /usr/bin/python3 -m pytest -q python/tests

if [ "${UWB_SKIP_SANITIZE:-0}" != "1" ]; then
  echo "[test] unit, regression and CLI tests under AddressSanitizer + UndefinedBehaviorSanitizer"
  # -O1 -g1 (the optimization ASan's documentation recommends, line tables for the reports): this build compiles
  # about 1.8 times faster than at -O2 -g (with the UBSan checks of cmake/UwbHelpers.cmake, about 3 times), and the
  # suite still runs in a few minutes under the sanitizers.
  if [ ! -f build-asan/CMakeCache.txt ]; then
    cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG" \
      -DUWB_SANITIZE=ON -DUWB_BUILD_BENCHMARKS=OFF -DUWB_BUILD_PYTHON=OFF
  fi
  cmake --build build-asan -j "$JOBS" 2>&1 | tee "$BUILD_LOG"
  no_warnings sanitizer
  # The CLI tests run the sanitized build-asan/uwbtdoa (UWB_CLI_PATH of that build): crafted inputs through the
  # whole program. Leak checks stay on; real-data evaluations (Slow*) stay in the Release run.
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --test-dir build-asan --output-on-failure -j "$JOBS" -LE slow -E "^Slow"
fi
echo "[test] all passed"
