#!/usr/bin/env bash
# tools/bench-vs-vkcube.sh on a small size: every vkcube frame rate and every ratio it prints must be a
# positive number (it once printed negative vkcube rates), and every model must get a ratio line.
#   bench_vs_vkcube_test.sh PROJBOT_EXECUTABLE
set -uo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
out=$(PROJBOT="$1" SIZES=640x480 bash "$here/tools/bench-vs-vkcube.sh" 300 2>&1) || { echo "$out"; echo "FAIL: the script failed"; exit 1; }
echo "$out"
echo "$out" | awk '
  $1 == "vkcube" { cubes++; if (!($3 + 0 > 0)) bad = bad "\n  vkcube rate not positive: " $0 }
  $NF ~ /^[0-9.eE+-]+$/ && $(NF - 1) == "ratio" {
    ratios++
    if (!($(NF) + 0 > 0) || !($4 + 0 > 0) || !($7 + 0 > 0)) bad = bad "\n  not positive: " $0
  }
  END {
    if (cubes != 1) bad = bad "\n  expected 1 vkcube line, got " cubes
    if (ratios != 2) bad = bad "\n  expected 2 ratio lines (duck, sphere100k), got " ratios
    if (bad != "") { print "FAIL:" bad; exit 1 }
    print "ok: " cubes " vkcube rate, " ratios " ratios, all positive"
  }'
