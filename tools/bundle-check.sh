#!/usr/bin/env bash
# Checks tools/bundle.sh the way the bundle is used: made into a new folder, under 64 MiB, then run in a root
# that holds nothing but the base the bundle assumes (glibc; no libstdc++, no Debian libraries) and, for the
# commands that draw, a Vulkan driver (here lavapipe and what it needs, standing in for the GPU's driver).
#   bash tools/bundle-check.sh
# Needs root (chroot) or unprivileged user namespaces (unshare -r); says so and fails without either.
set -euo pipefail
cd "$(dirname "$0")/.."

fail() { echo "bundle-check: FAILED: $*" >&2; exit 1; }
work=$(mktemp -d /tmp/projbot-bundle-check.XXXXXX)
trap 'rm -rf "$work"' EXIT

# Into the root with its own /proc (the loader and $ORIGIN read /proc/self/exe), in a mount namespace that
# ends with the command.
root="$work/root"
chroot=$(command -v chroot) || fail "no chroot (coreutils)"
unshare=$(command -v unshare) || fail "no unshare (util-linux)"
enter=("$unshare" -m -p -f --mount-proc="$root/proc" "$chroot")
[[ $(id -u) -eq 0 ]] || enter=("$unshare" -r -m -p -f --mount-proc="$root/proc" "$chroot")
mkdir -p "$root/proc"
"${enter[@]}" / true 2>/dev/null || fail "needs root or user namespaces (unshare -r) to run the bundle in a bare root"

bash tools/bundle.sh "$work/bundle" | tee "$work/bundle.log"
size=$(tail -1 "$work/bundle.log" | sed -n 's/^bundle: \([0-9.]*\) MiB in .*/\1/p')
[[ -n "$size" ]] || fail "bundle.sh did not print its size last"
awk -v s="$size" 'BEGIN { exit !(s < 64) }' || fail "the bundle is $size MiB, over 64"
"$work/bundle/run.sh" --version | grep -q "portable build" || fail "run.sh --version does not name the portable build"

# The bare root: glibc (ld-linux, libc, libm and its compatibility stubs libdl, libpthread, librt, ...), the bundle (unpacked by run.sh above) and a folder for outputs.
mkdir -p "$root/lib64" "$root/lib/x86_64-linux-gnu" "$root/out" "$root/tmp"
cp -L /lib64/ld-linux-x86-64.so.2 "$root/lib64/"
for so in libc.so.6 libm.so.6 libdl.so.2 libpthread.so.0 librt.so.1 libresolv.so.2 libutil.so.1; do
  cp -L "/lib/x86_64-linux-gnu/$so" "$root/lib/x86_64-linux-gnu/"
done
cp -a "$work/bundle" "$root/bundle"
# run.sh's environment where the machine has no libstdc++ (the root has no shell to run run.sh itself).
in_root() {
  env -i PROJBOT_ASSETS=/bundle/assets LD_LIBRARY_PATH=/bundle/lib:/bundle/lib/fallback VK_ADD_LAYER_PATH=/bundle/layers "$@"
}

# 1. Every library the executable links comes from the bundle (no driver in the root yet).
in_root "${enter[@]}" "$root" /bundle/projbot --version >"$work/version.txt" 2>&1 || {
  cat "$work/version.txt" >&2
  fail "the bundle's projbot does not start in a root with only glibc"
}
echo "bundle-check: starts with glibc alone: $(cat "$work/version.txt")"
rc=0
in_root "${enter[@]}" "$root" /bundle/projbot calibrate solve /out 2>"$work/left_out.txt" || rc=$?
[[ $rc -eq 69 ]] || fail "calibrate solve, left out of the bundle, exited $rc (not 69)"
grep -q "not in this build" "$work/left_out.txt" || fail "calibrate solve does not say it is not in this build"

# 2. The driver: lavapipe's ICD and the libraries it loads, as a GPU machine's driver brings its own.
icd=$(ls /usr/share/vulkan/icd.d/lvp_icd.*.json | head -1)
lvp=$(sed -n 's/.*"library_path": *"\([^"]*\)".*/\1/p' "$icd")
mkdir -p "$root/icd"
sed "s#\"library_path\": *\"[^\"]*\"#\"library_path\": \"$lvp\"#" "$icd" >"$root/icd/lvp.json"
for f in "$lvp" $(ldd "$lvp" | awk '$3 ~ /^\// { print $3 }'); do
  mkdir -p "$root$(dirname "$f")"
  cp -L "$f" "$root$f"
done
driver() { in_root VK_ICD_FILENAMES=/icd/lvp.json "${enter[@]}" "$root" /bundle/projbot "$@"; }

driver render --out /out/frame.png --validation >"$work/render.txt" 2>&1 || { cat "$work/render.txt" >&2; fail "render"; }
grep -q "validation: 0 errors" "$work/render.txt" || { cat "$work/render.txt" >&2; fail "render under validation"; }
[[ -s "$root/out/frame.png" ]] || fail "render wrote no PNG"
echo "bundle-check: render: $(grep -c . "$work/render.txt") lines, $(stat -c %s "$root/out/frame.png") bytes of PNG"
driver bench render --frames 20 --sizes 640x400 --offscreen-only >"$work/bench.txt" 2>&1 || { cat "$work/bench.txt" >&2; fail "bench render"; }
driver run --headless --sim --visits 1 --dwell 1 >"$work/run.txt" 2>&1 || { cat "$work/run.txt" >&2; fail "run --headless --sim"; }
grep -q "odometry alone" "$work/run.txt" || fail "run --sim does not say the robot runs on odometry"
grep -E "fps|error" "$work/run.txt" | head -4
echo "bundle-check: passed ($size MiB)"
