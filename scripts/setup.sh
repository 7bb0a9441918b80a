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
          python3-matplotlib python3-pytest python3-yaml libzmq3-dev cppzmq-dev python3-zmq libboost-dev)
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
# Progress from ninja's status prefix "[done/total elapsed]" (a bash loop: awk would buffer its input).
progress() {
  local last=-100 line done total t left
  while IFS= read -r line; do
    if [[ $line =~ ^\[([0-9]+)/([0-9]+)\ ([0-9]+)(\.[0-9]+)?\]\  ]]; then
      done=${BASH_REMATCH[1]}; total=${BASH_REMATCH[2]}; t=${BASH_REMATCH[3]}
      ((done == 0)) && continue
      if ((done == total || t - last >= 15)); then
        left=$((done > 0 ? t * (total - done) / done : 0))
        echo "[setup] $what: step $done of $total, ${t} s elapsed, about ${left} s left"
        last=$t
      fi
    elif [[ $line == "ninja: no work to do." ]]; then
      echo "[setup] $what is up to date"
    fi
  done
}
NINJA_STATUS="[%f/%t %e] " cmake --build "$BUILD_DIR" -j "$JOBS" "${TARGET_ARGS[@]}" 2>&1 | tee "$LOG" | progress
status=${PIPESTATUS[0]}
set -e
if [ "$status" -ne 0 ]; then
  echo "[setup] build failed; the errors:" >&2
  grep -E "error|Error|FAILED" -A3 "$LOG" | head -60 >&2
  exit "$status"
fi
echo "[setup] built $what"
