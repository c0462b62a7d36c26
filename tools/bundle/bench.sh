#!/bin/sh
# The benchmarks of the GPU bundle's page (docs/gpu-bundle.md), run from a bundle (tools/bundle.sh) on the machine it was
# carried to; each one's table goes to OUT/NAME.txt as it prints, and OUT/summary.txt gathers their
# headline lines with the machine named.
#   DIR/bench.sh OUT [--quick]
# OUT must be new or empty. --quick runs each benchmark briefly (a check that they all run). Windowed
# runs need a display ($DISPLAY); without one, only the offscreen ones run, and the summary says so.
set -u
here=$(cd "$(dirname "$0")" && pwd)
out=${1:-}
[ -n "$out" ] || { echo "usage: $0 OUT [--quick]" >&2; exit 2; }
if [ -e "$out" ] && [ -n "$(ls -A "$out" 2>/dev/null)" ]; then
  echo "bench.sh: $out is not empty; name a new folder" >&2
  exit 2
fi
mkdir -p "$out" || exit 2
frames=2000 visits=5 track=300 motion_visits=   # bench motion: the scene's list of motions once
[ "${2:-}" = "--quick" ] && frames=60 visits=1 track=30 motion_visits="--visits 1"
status=0

bench() {  # NAME, then projbot's arguments
  name=$1
  shift
  echo "== $name: projbot $*"
  "$here/run.sh" "$@" >"$out/$name.txt" 2>&1
  code=$?
  cat "$out/$name.txt"
  [ $code -eq 0 ] || { echo "bench.sh: $name exited $code" >&2; status=1; }
}

{
  echo "projbot bench, $(date -u '+%Y-%m-%d %H:%M UTC'), $("$here/run.sh" --version)"
  command -v nvidia-smi >/dev/null 2>&1 && nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader
  echo "cpu: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cores"
} >"$out/machine.txt"
cat "$out/machine.txt"

windowed=--offscreen-only
[ -n "${DISPLAY:-}" ] && windowed=
bench validation render --size 1920x1080 --out "$out/frame.png" --validation
bench render bench render --frames "$frames" --sizes 1280x800,1920x1080 $windowed
bench render_lens bench render --frames "$frames" --sizes 1920x1080 --offscreen-only --lens 0.1,0.02 --compensation
bench track bench track --frames "$track"
bench motion bench motion $motion_visits --dwell 2
bench live run --headless --sim --visits "$visits" --dwell 2.5 --profile "$out/live_profile.csv"

{
  cat "$out/machine.txt"
  [ -n "$windowed" ] && echo "windowed runs: not made (no display)"
  for f in validation render render_lens track motion live; do
    echo "--- $f"
    grep -v "visits done\|^prediction" "$out/$f.txt"
  done
} >"$out/summary.txt"
echo "bench.sh: tables in $out (summary.txt first)"
exit $status
