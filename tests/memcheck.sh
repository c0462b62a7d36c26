#!/usr/bin/env bash
# Runs a command under valgrind's memcheck, where valgrind can run the executable at all.
#   memcheck.sh VALGRIND SUPPRESSIONS EXECUTABLE [ARGS...]
# Exit 0: no memory error. Exit 9: memcheck found errors (the test fails). Exit 77: valgrind cannot
# run the executable on this machine (ctest reports the test as skipped; the reason is printed).
#
# Why the probe: valgrind 3.19 (Debian 12) dies with SIGILL before main on CPUs whose instructions it
# does not decode, e.g. libhwy (pulled in by libjxl) picks AVX-512 code at load time on AMD EPYC.
# That says nothing about our code, so it is a skip, never a pass; the same align path is checked
# under AddressSanitizer by tools/test.sh on every machine.
set -uo pipefail
valgrind=$1 supp=$2 exe=$3
shift 3
flags=(--error-exitcode=9 --quiet --suppressions="$supp")

probe_log=$(mktemp)
trap 'rm -f "$probe_log"' EXIT
("$valgrind" "${flags[@]}" "$exe" --version; exit $?) >"$probe_log" 2>&1  # not exec: its shell reports a SIGILL into the log
probe=$?
if ((probe == 9)); then
  echo "memcheck: memory errors in '$exe --version' itself:" >&2
  cat "$probe_log" >&2
  exit 9
fi
if ((probe != 0)); then
  reason=$(grep -m2 -E 'SIGILL|Illegal|unhandled instruction|unrecognised instruction|signal [0-9]+' "$probe_log" | tr '\n' ' ')
  echo "memcheck: SKIPPED: valgrind cannot run $exe on this machine (probe exit $probe): ${reason:-$(tail -n 3 "$probe_log")}"
  exit 77
fi
exec "$valgrind" "${flags[@]}" "$exe" "$@"
