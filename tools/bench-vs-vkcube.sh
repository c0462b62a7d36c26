#!/usr/bin/env bash
# Runs vkcube (vulkan-tools) and `projbot bench render --windowed-only` at the same sizes, in one
# Xvfb, and prints our windowed frame rate for each model as a ratio of vkcube's. Needs a Release build.
#   bash tools/bench-vs-vkcube.sh [FRAMES]      (default 600 vkcube frames, 300 projbot frames)
set -euo pipefail
cd "$(dirname "$0")/.."
frames=${1:-600}
(( frames > 100 )) || { echo "FRAMES must be over 100"; exit 2; }
projbot=build/release/tools/projbot
[[ -x $projbot ]] || { cmake --preset release >/dev/null && cmake --build --preset release --target projbot; }
sizes=(1280x800 1920x1080)

run() {
  for size in "${sizes[@]}"; do
    w=${size%x*}; h=${size#*x}
    # Two runs, 100 and $frames frames: the difference cancels vkcube's start-up.
    t0=$(date +%s.%N)
    vkcube --c 100 --width "$w" --height "$h" --present_mode 0 --suppress_popups >/dev/null 2>&1
    t1=$(date +%s.%N)
    vkcube --c "$frames" --width "$w" --height "$h" --present_mode 0 --suppress_popups >/dev/null 2>&1
    t2=$(date +%s.%N)
    echo "vkcube $size $(echo "($frames - 100) / (($t2 - $t1) - ($t1 - $t0))" | bc -l)"
  done
  "$projbot" bench render --windowed-only --sizes "$(IFS=,; echo "${sizes[*]}")"
}

out=$(xvfb-run -a -s "-screen 0 2048x1152x24" bash -c "$(declare -f run); frames=$frames projbot=$projbot sizes=(${sizes[*]}); run")
echo "$out"
echo
echo "projbot windowed fps as a ratio of vkcube's (vkcube: $frames minus 100 frames, start-up cancelled):"
echo "$out" | awk '
  $1 == "vkcube" { cube[$2] = $3 }
  $4 == "window" { printf "  %-11s %-10s projbot %7.1f fps  vkcube %7.1f fps  ratio %.2f\n", $1, $3, $5, cube[$3], $5 / cube[$3] }'
