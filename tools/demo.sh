#!/usr/bin/env bash
# Quick start, command 1: install what is missing, build (Release), and run the main job on the
# built-in default: the demo tour in the digital twin (two targets, three visits each), printing the
# projection error at the markers beside the paper's Table 1; report and projector frames in out/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup-debian.sh
cmake --preset release >/dev/null
cmake --build --preset release --target projbot
mkdir -p out
./build/release/tools/projbot tour --report out/tour.json --frames out/tour "$@"
