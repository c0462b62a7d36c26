#!/usr/bin/env bash
# How long each long command takes to stop after Ctrl-C (SIGINT) or SIGTERM (issue 72's goal: within 1 s,
# wherever it is). Each command is started, signalled after each of the delays (loading, a first trial,
# steady work), and timed from the signal to its exit; its exit status is printed beside (130 / 143
# expected). Prints one row per run and, last, the slowest stop. Nothing is asserted: figures move with the
# machine's load, so say what ran beside when you quote them.
#
#   bash tools/stop-times.sh [--projbot PATH] [--delays "0.3 2 6"] [--only WORD] [--signals "INT TERM"]
#     --projbot PATH  the executable (default build/release/tools/projbot)
#     --delays LIST   seconds after the start to send the signal (default "0.3 2 6")
#     --only WORD     only the commands whose line holds WORD
#     --signals LIST  INT, TERM or both (default both)
# Outputs go to a fresh temporary folder, removed at the end.
set -euo pipefail
cd "$(dirname "$0")/.."
projbot=build/release/tools/projbot
delays="0.3 2 6"
only=
signals="INT TERM"
usage() { sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//'; exit 2; }
while (($#)); do
  case $1 in
    --projbot) projbot=${2:?--projbot needs a path}; shift 2 ;;
    --delays) delays=${2:?--delays needs a list}; shift 2 ;;
    --only) only=${2:?--only needs a word}; shift 2 ;;
    --signals) signals=${2:?--signals needs INT, TERM or both}; shift 2 ;;
    -h|--help) usage ;;
    *) echo "stop-times: unknown argument '$1'" >&2; usage ;;
  esac
done
[[ -x $projbot ]] || { echo "stop-times: $projbot is not an executable (build it: cmake --build --preset release)" >&2; exit 2; }
data=../shared/data
[[ -d $data ]] || { echo "stop-times: $data is missing beside the project" >&2; exit 2; }
for d in $delays; do [[ $d =~ ^[0-9]+(\.[0-9]+)?$ ]] || { echo "stop-times: --delays: '$d' is not a number of seconds" >&2; exit 2; }; done
work=$(mktemp -d "${TMPDIR:-/tmp}/projbot_stop_times.XXXXXX")
trap 'rm -rf "$work"' EXIT
set -m  # background jobs keep SIGINT (without job control bash starts them with it ignored)

# Each line: a label, then the command's arguments ({w} is a fresh output folder for the run).
commands=(
  "render-bench|bench render --frames 100000 --offscreen-only"
  "bench-track|bench track --frames 100000"
  "bench-motion|bench motion --visits 40"
  "bench-appearance|bench appearance --visits 40"
  "bench-content|bench content --seconds 600"
  "bench-acquire|bench acquire --trials 200"
  "bench-dataset|bench dataset $data/ycbv-bop"
  "bench-dataset-track|bench dataset $data/ycbv-bop --track"
  "bench-sensor|bench sensor $data/ycbv-bop"
  "bench-localize|bench localize --stops 30"
  "twin-dataset|twin-dataset --out {w}/twin --scenes 50"
  "slam|slam --rawlog $data/mrpt/range_030_bearing_015.rawlog --out-map {w}/map --out-trajectory {w}/t.txt"
  "localize|localize --map $work/map0 --rawlog $data/mrpt/range_030_bearing_015.rawlog --out-trajectory {w}/l.txt"
  "tour|tour"
  "run-sim|run --sim --headless"
  "record|record --out {w}/rec"
  "calibrate-simulate|calibrate simulate --out {w}/cap --poses 60"
  "calibrate-photometric|calibrate photometric --sim --out {w}/p.yaml"
)

now() { date +%s.%N; }
if [[ -z $only || localize == *"$only"* ]]; then  # localize needs a map: the short loop's, made once
  "$projbot" slam --rawlog "$data/mrpt/2006-01ENE-21-SENA_Telecom_Faculty_one_loop_only.rawlog" --out-map "$work/map0" \
    --out-trajectory "$work/t0.txt" >"$work/map0.log" 2>&1 || { cat "$work/map0.log"; echo "stop-times: slam for localize's map failed" >&2; exit 1; }
fi
slowest=0
slowest_at=
printf '%-22s %-6s %-7s %-6s %s\n' command signal after_s exit stop_s
for line in "${commands[@]}"; do
  label=${line%%|*}
  args=${line#*|}
  [[ -n $only && $line != *"$only"* ]] && continue
  for sig in $signals; do
    for delay in $delays; do
      w=$work/$label-$sig-$delay
      mkdir -p "$w"
      # shellcheck disable=SC2086 # the arguments are words
      "$projbot" ${args//\{w\}/$w} >"$w.log" 2>&1 &
      pid=$!
      sleep "$delay"
      if ! kill -0 "$pid" 2>/dev/null; then
        wait "$pid" && rc=0 || rc=$?
        printf '%-22s %-6s %-7s %-6s %s\n' "$label" "$sig" "$delay" "$rc" "ended before the signal"
        continue
      fi
      sent=$(now)
      kill -s "$sig" "$pid"
      stopped=
      for _ in $(seq 3000); do  # 30 s at most
        kill -0 "$pid" 2>/dev/null || { stopped=$(now); break; }
        sleep 0.01
      done
      if [[ -z $stopped ]]; then
        kill -KILL "$pid" 2>/dev/null || true
        wait "$pid" 2>/dev/null || true
        printf '%-22s %-6s %-7s %-6s %s\n' "$label" "$sig" "$delay" "-" "did not stop within 30 s (killed)"
        slowest=30 slowest_at="$label $sig after $delay s"
        continue
      fi
      wait "$pid" && rc=0 || rc=$?
      took=$(awk -v a="$sent" -v b="$stopped" 'BEGIN { printf "%.2f", b - a }')
      printf '%-22s %-6s %-7s %-6s %s\n' "$label" "$sig" "$delay" "$rc" "$took"
      if awk -v t="$took" -v s="$slowest" 'BEGIN { exit !(t > s) }'; then slowest=$took slowest_at="$label $sig after $delay s"; fi
    done
  done
done
echo "slowest stop: $slowest s ($slowest_at)"
