#!/usr/bin/env bash
# Checks tools/bundle.sh the way the bundle is used: made into a new folder, under 64 MiB, then run in a root
# that holds nothing but the base the bundle assumes (glibc; no libstdc++, no Debian libraries) and, for the
# commands that draw, a Vulkan driver (here lavapipe and what it needs, standing in for the GPU's driver).
#   bash tools/bundle-check.sh [--enter auto|namespaces|chroot]
# The root is entered through new mount and pid namespaces with their own /proc where the kernel gives them
# (as root, or unprivileged through unshare -r); else, as root, by plain chroot with /proc mounted in the root
# (or, where mounting is refused too, as in a container without CAP_SYS_ADMIN, without /proc: the bundle's
# libraries are found through LD_LIBRARY_PATH, not $ORIGIN). --enter forces one way (to check the other).
# Where no way works (not root, no user namespaces, or chroot refused) it says "bundle-check: SKIPPED: why"
# and exits 77, which tools/test.sh reports as skipped, not failed.
set -euo pipefail
cd "$(dirname "$0")/.."

enter_how=auto
case "${1:-}" in
  "") ;;
  --enter) enter_how=${2:-}; [[ $enter_how =~ ^(auto|namespaces|chroot)$ ]] || { echo "bundle-check: --enter takes auto, namespaces or chroot, not '$enter_how'" >&2; exit 2; } ;;
  -h | --help) sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
  *) echo "bundle-check: unknown argument '$1' (usage: bash tools/bundle-check.sh [--enter auto|namespaces|chroot])" >&2; exit 2 ;;
esac

fail() { echo "bundle-check: FAILED: $*" >&2; exit 1; }
skip() { echo "bundle-check: SKIPPED: $*"; exit 77; }
work=$(mktemp -d /tmp/projbot-bundle-check.XXXXXX)
root="$work/root"
proc_mounted=0
cleanup() {
  ((proc_mounted == 0)) || umount -l "$root/proc" 2>/dev/null || true
  rm -rf --one-file-system "$work"
}
trap cleanup EXIT

chroot=$(command -v chroot) || skip "no chroot (coreutils) to run the bundle in a bare root"
mkdir -p "$root/proc"
# Namespaces: the root's own /proc (the loader and $ORIGIN read /proc/self/exe) in a mount namespace that
# ends with the command.
enter=()
if [[ $enter_how != chroot ]] && unshare=$(command -v unshare); then
  enter=("$unshare" -m -p -f --mount-proc="$root/proc" "$chroot")
  [[ $(id -u) -eq 0 ]] || enter=("$unshare" -r -m -p -f --mount-proc="$root/proc" "$chroot")
  if "${enter[@]}" / true 2>/dev/null; then how="namespaces (unshare), the root's own /proc"; else enter=(); fi
fi
if ((${#enter[@]} == 0)); then
  [[ $enter_how != namespaces ]] || skip "--enter namespaces: unshare -m -p is refused here"
  [[ $(id -u) -eq 0 ]] || skip "not root and no user namespaces (unshare -r): cannot enter a bare root"
  "$chroot" / true 2>/dev/null || skip "chroot is refused here (no CAP_SYS_CHROOT), and so are namespaces"
  enter=("$chroot")
  if mount -t proc proc "$root/proc" 2>/dev/null; then
    proc_mounted=1
    how="plain chroot (no namespaces here), /proc mounted in the root"
  else
    how="plain chroot (no namespaces here), without /proc (mounting it is refused)"
  fi
fi
echo "bundle-check: entering the bare root by $how"

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
