#!/usr/bin/env bash
# Quick start, command 2 (and CI): install what is missing, build everything with warnings as errors,
# check formatting, and run the whole test suite (GPU tests on lavapipe, window tests under Xvfb).
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup-debian.sh
bash tools/check-format.sh
cmake --preset ci >/dev/null
cmake --build --preset ci
ctest --preset ci
