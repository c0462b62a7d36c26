#!/usr/bin/env bash
# Quick start, command 2 (and CI): install what is missing, build everything with warnings as errors,
# check formatting, check the align path and the hostile-input suite for memory errors under
# AddressSanitizer + UBSan (on every machine; valgrind's memcheck in the main suite is skipped where
# valgrind cannot run the executable, see docs/building.md), run the whole test suite (GPU tests on lavapipe,
# window tests under Xvfb), then every fuzz target for a short smoke run (its seeds include every
# earlier finding), then the portable bundle (tools/bundle-check.sh; skipped, with its reason, where no bare
# root can be entered).
set -euo pipefail
cd "$(dirname "$0")/.."
# ccache keys without this checkout's absolute path, so a fresh clone (CI's) reuses earlier compiles.
export CCACHE_BASEDIR=$PWD CCACHE_NOHASHDIR=true
bash tools/setup-debian.sh
bash tools/check-format.sh
cmake --preset ci >/dev/null
cmake --build --preset ci
cmake --preset asan >/dev/null
cmake --build --preset asan --target projbot hostile_test
ctest --preset asan-memory
status=0
ctest --preset ci || status=$?
# ctest does not show a skipped test's output: say why each one was skipped.
grep -h '^[a-z]*: SKIPPED:' build/ci/Testing/Temporary/LastTest.log 2>/dev/null || true
# The smoke run's mutations are seeded: it replays every earlier finding and the same fresh inputs each time.
# (Unseeded, a 15 s run once stopped CI on an ASan allocator check inside FFmpeg's uninstrumented mov
# demuxer that no rerun reproduced; exploring is tools/fuzz.sh's own job, unseeded.)
PROJBOT_FUZZ_SEED=${PROJBOT_FUZZ_SEED:-1} bash tools/fuzz.sh all "${PROJBOT_FUZZ_SMOKE_SECONDS:-15}" || status=1
# The portable bundle (issue 45): built, under 64 MiB, and run in a root with nothing but glibc and a driver.
# Where no bare root can be entered (no namespaces, no chroot) it says why and exits 77: skipped, not failed.
bundle_rc=0
bash tools/bundle-check.sh || bundle_rc=$?
case $bundle_rc in
  0) ;;
  77) echo "test: the bundle check was skipped (the reason is above); everything else decides the exit status" ;;
  *) status=1 ;;
esac
exit "$status"
