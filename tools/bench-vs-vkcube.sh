#!/usr/bin/env bash
# Runs vkcube (vulkan-tools) and `projbot bench render --windowed-only` at the same sizes, in one
# Xvfb, and prints our windowed frame rate for each model as a ratio of vkcube's. Needs a Release build
# (or PROJBOT=path/to/projbot).
#   bash tools/bench-vs-vkcube.sh [FRAMES]      (default 600 vkcube frames, 300 projbot frames)
#
# vkcube's frame rate comes from Mesa's overlay layer (VK_LAYER_MESA_overlay, in mesa-vulkan-drivers):
# it counts presents inside vkcube in 200 ms windows, so start-up is not in it; the median of the
# windows after the first is reported. (Timing two vkcube runs and subtracting, as before, went
# negative when start-up noise on 2 cores exceeded the difference.) Without the layer, the whole run's
# frames over its wall time is reported instead: start-up included, so low, but never negative.
set -euo pipefail
cd "$(dirname "$0")/.."
frames=${1:-600}
(( frames >= 100 )) || { echo "FRAMES must be at least 100"; exit 2; }
projbot=${PROJBOT:-build/release/tools/projbot}
[[ -x $projbot ]] || { cmake --preset release >/dev/null && cmake --build --preset release --target projbot; }
sizes=(1280x800 1920x1080)
[[ -n ${SIZES:-} ]] && IFS=, read -r -a sizes <<<"$SIZES"

run() {
  for size in "${sizes[@]}"; do
    w=${size%x*}; h=${size#*x}
    csv=$(mktemp)
    t0=$(date +%s.%N)
    VK_INSTANCE_LAYERS=VK_LAYER_MESA_overlay VK_LAYER_MESA_OVERLAY_CONFIG="output_file=$csv,fps_sampling_period=200,no_display" \
      vkcube --c "$frames" --width "$w" --height "$h" --present_mode 0 --suppress_popups >/dev/null 2>&1
    t1=$(date +%s.%N)
    # Rows after the header and the first window; median of the fps column.
    fps=$(tail -n +3 "$csv" | cut -d, -f3 | sort -g | awk '{ v[NR] = $1 } END { if (NR) print (NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2) }')
    how="median of $(($(wc -l <"$csv") - 2)) 200 ms windows"
    if [[ -z $fps ]]; then
      fps=$(echo "$frames / ($t1 - $t0)" | bc -l)
      how="whole run, start-up included (no overlay layer data)"
    fi
    rm -f "$csv"
    printf 'vkcube %s %.1f %s\n' "$size" "$fps" "$how"
  done
  "$projbot" bench render --windowed-only --sizes "$(IFS=,; echo "${sizes[*]}")"
}

out=$(xvfb-run -a -s "-screen 0 2048x1152x24" bash -c "$(declare -f run); frames=$frames projbot=$projbot sizes=(${sizes[*]}); run")
echo "$out"
echo
echo "projbot windowed fps as a ratio of vkcube's (vkcube: $frames frames, fps from Mesa's overlay layer):"
echo "$out" | awk '
  $1 == "vkcube" { cube[$2] = $3 }
  $4 == "window" { printf "  %-11s %-10s projbot %7.1f fps  vkcube %7.1f fps  ratio %.2f\n", $1, $3, $5, cube[$3], $5 / cube[$3] }'
