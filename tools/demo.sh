#!/usr/bin/env bash
# Quick start, command 1: install what is missing, build (Release), and run the main job on the
# built-in default: render the demo scene headless to out/demo.png and print the frame-time summary.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup-debian.sh
cmake --preset release >/dev/null
cmake --build --preset release --target projbot
mkdir -p out
./build/release/tools/projbot render --out out/demo.png --frames 120 "$@"
