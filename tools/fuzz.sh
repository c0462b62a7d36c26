#!/usr/bin/env bash
# Fuzzes the glTF loader with libFuzzer (clang) for SECONDS (default 60), seeded with the shared models.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
command -v clang++ >/dev/null || { echo "fuzz: needs clang (apt-get install clang)"; exit 1; }
cmake --preset fuzz >/dev/null
cmake --build --preset fuzz --target fuzz_gltf
corpus=build/fuzz/corpus
mkdir -p "$corpus"
find ../shared/data/gltf -name '*.gl*' -exec cp -n {} "$corpus/" \; 2>/dev/null || true
./build/fuzz/tests/fuzz/fuzz_gltf -max_total_time="$seconds" -max_len=200000 -rss_limit_mb=4096 "$corpus"
