#!/usr/bin/env bash
# Installs the Debian packages uwbtdoa needs (only those missing) and builds it in Release into build/.
# Idempotent: a second run installs nothing and rebuilds only what changed.
#
#   scripts/setup.sh [cmake options...]   env: UWB_JOBS, UWB_BUILD_DIR, UWB_TARGETS, UWB_QUIET, UWB_PACKAGES_ONLY
#
# UWB_TARGETS: build only these targets (default: everything: library, CLI, tests, benchmarks, Python module).
# UWB_QUIET=1: print one progress line (steps done, time elapsed and left) instead of the compiler's output; the
# full log goes to $UWB_BUILD_DIR/build.log and is shown only when the build fails.
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(build-essential cmake ninja-build libeigen3-dev libcli11-dev nlohmann-json3-dev libfmt-dev
          libgtest-dev libgmock-dev libbenchmark-dev pybind11-dev python3-dev python3-numpy
          python3-matplotlib python3-pytest)
# Only for scripts/fuzz.sh (libFuzzer harnesses need clang): installed when UWB_WITH_CLANG=1.
CLANG_PACKAGES=(clang-14 libclang-rt-14-dev)
[ "${UWB_WITH_CLANG:-0}" = "1" ] && PACKAGES+=("${CLANG_PACKAGES[@]}")
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "[setup] installing ${#missing[@]} Debian package(s): ${missing[*]}"
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
else
  echo "[setup] all Debian packages present"
fi

[ "${UWB_PACKAGES_ONLY:-0}" = "1" ] && exit 0

JOBS="${UWB_JOBS:-$(nproc)}"
BUILD_DIR="${UWB_BUILD_DIR:-build}"
if [ ! -f "$BUILD_DIR/CMakeCache.txt" ]; then
  echo "[setup] configuring $BUILD_DIR (Release)"
  cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release -DPython3_EXECUTABLE=/usr/bin/python3 "$@" >/dev/null
fi
read -r -a TARGETS <<< "${UWB_TARGETS:-}"
TARGET_ARGS=()
((${#TARGETS[@]})) && TARGET_ARGS=(--target "${TARGETS[@]}")

if [ "${UWB_QUIET:-0}" != "1" ]; then
  cmake --build "$BUILD_DIR" -j "$JOBS" "${TARGET_ARGS[@]}"
  exit 0
fi

LOG="$BUILD_DIR/build.log"
what="${UWB_TARGETS:-everything}"
echo "[setup] building $what with $JOBS job(s); log: $LOG"
set +e
NINJA_STATUS="[%f/%t %e] " cmake --build "$BUILD_DIR" -j "$JOBS" "${TARGET_ARGS[@]}" 2>&1 | tee "$LOG" |
  awk -v what="$what" '
    /^\[[0-9]+\/[0-9]+ [0-9.]+\] / {
      split(substr($1, 2), a, "/"); done = a[1] + 0; total = a[2] + 0; t = $2; sub(/\]/, "", t); t += 0
      if (done == total || t - last >= 15 || done == 1) {
        left = done > 0 ? t / done * (total - done) : 0
        printf "[setup] %s: step %d of %d, %d s elapsed, about %d s left\n", what, done, total, t, left
        last = t; fflush()
      }
    }
    /^ninja: no work to do/ { printf "[setup] %s is up to date\n", what }'
status=${PIPESTATUS[0]}
set -e
if [ "$status" -ne 0 ]; then
  echo "[setup] build failed; the errors:" >&2
  grep -E "error|Error|FAILED" -A3 "$LOG" | head -60 >&2
  exit "$status"
fi
echo "[setup] built $what"
