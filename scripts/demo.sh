#!/usr/bin/env bash
# README command 1: install, build, run the built-in default demo.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
exec build/uwbtdoa demo "$@"
