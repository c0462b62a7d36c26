#!/usr/bin/env bash
# Fuzzes one reader of user files with libFuzzer (clang + AddressSanitizer):
#   tools/fuzz.sh TARGET [SECONDS]     TARGET: gltf scene pcd ply depth_png depth_tiff oni rawlog ini mesh bop video, or all
# Seeds: tests/fuzz/corpus/TARGET (committed) plus, for gltf, the shared models. The growing corpus is
# build/fuzz/corpus/TARGET; a finding (crash, ASan report, allocation over 512 MB, 10 s on one input) is
# saved under build/fuzz/findings/TARGET/ and the script exits 1: make it a regression test. A failure of the
# harness itself (its own file writes: exit 86, "HARNESS FAILURE") is said as such, saves no finding, and exits 3.
# With "all", every target runs and the last line counts the targets with findings and with harness failures.
set -euo pipefail
cd "$(dirname "$0")/.."
targets=(gltf scene pcd ply depth_png depth_tiff oni rawlog ini mesh bop video)
usage() { echo "usage: tools/fuzz.sh TARGET [SECONDS]   (TARGET: ${targets[*]} or all; SECONDS default 60)"; exit 2; }
[[ $# -ge 1 ]] || usage
target=$1
seconds=${2:-60}
[[ $seconds =~ ^[0-9]+$ && $seconds -gt 0 ]] || { echo "fuzz: SECONDS must be a whole number > 0, not '$seconds'"; exit 2; }
if [[ $target == all ]]; then
  found=() broken=()
  for t in "${targets[@]}"; do
    rc=0
    bash "$0" "$t" "$seconds" || rc=$?
    ((rc == 0)) || { ((rc == 3)) && broken+=("$t") || found+=("$t"); }
  done
  echo "fuzz: ${#targets[@]} targets, findings in ${#found[@]}${found:+ (${found[*]})}, harness failures in ${#broken[@]}${broken:+ (${broken[*]})}"
  ((${#found[@]} + ${#broken[@]} == 0)) || exit 1
  exit 0
fi
[[ " ${targets[*]} " == *" $target "* ]] || { echo "fuzz: unknown target '$target'"; usage; }
command -v clang++ >/dev/null || { echo "fuzz: needs clang (apt-get install clang)"; exit 1; }
export CCACHE_BASEDIR=$PWD CCACHE_NOHASHDIR=true
mkdir -p build
( # one build at a time: several fuzzers may start side by side
  flock 9
  cmake --preset fuzz >/dev/null
  cmake --build --preset fuzz --target "fuzz_$target" | grep -v '^\[' || true
) 9>build/.fuzz-build.lock
[[ -x build/fuzz/tests/fuzz/fuzz_$target ]] || { echo "fuzz: fuzz_$target did not build"; exit 1; }

corpus=build/fuzz/corpus/$target
findings=build/fuzz/findings/$target
mkdir -p "$corpus" "$findings"
cp -n tests/fuzz/corpus/"$target"/* "$corpus"/
if [[ $target == gltf ]]; then find ../shared/data/gltf -name '*.gl*' -size -300k -exec cp -n {} "$corpus/" \; 2>/dev/null || true; fi
# Readers must refuse what would need more than 512 MB for one allocation (a length field's claim). The
# rawlog reader's MRPT child is capped like the release build's address-space limit: ASan fails an
# allocation over 1 GB with bad_alloc, which the child reports as an error.
export ASAN_OPTIONS="allocator_may_return_null=1:max_allocation_size_mb=1024:detect_leaks=0:${ASAN_OPTIONS:-}"
malloc_limit=512
[[ $target == rawlog ]] && malloc_limit=2048
# PROJBOT_FUZZ_SEED fixes libFuzzer's mutation sequence (CI's smoke run: the same inputs every time, so a
# red CI is a change's, not a dice roll's); unset, each run explores anew.
seed=()
[[ -n ${PROJBOT_FUZZ_SEED:-} ]] && seed=(-seed="$PROJBOT_FUZZ_SEED")
log=build/fuzz/$target.log
set +e
start=$(date +%s)
"./build/fuzz/tests/fuzz/fuzz_$target" "${seed[@]}" -max_total_time="$seconds" -max_len=65536 -timeout=10 -rss_limit_mb=3072 \
  -malloc_limit_mb=$malloc_limit -artifact_prefix="$findings/" -print_final_stats=1 "$corpus" >"$log" 2>&1
status=$?
elapsed=$(($(date +%s) - start))
((elapsed > 0)) || elapsed=1
set -e
runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -1 || echo 0)
echo "fuzz $target: $runs inputs in $elapsed s ($((runs / elapsed)) per second), corpus $(ls "$corpus" | wc -l) files, exit $status (log: $log)"
if [[ $status -eq 86 ]] || grep -q 'projbot-fuzz: HARNESS FAILURE' "$log"; then
  grep -m1 'projbot-fuzz: HARNESS FAILURE' "$log" || echo "fuzz $target: the harness exited 86 without saying why"
  echo "fuzz $target: a failure of the harness, not a finding in the reader; nothing saved under $findings"
  exit 3
fi
if [[ $status -ne 0 ]]; then
  grep -E 'ERROR|SUMMARY|Test unit written' "$log" | head -5
  exit 1
fi
