#!/usr/bin/env bash
# The README's quick start on a fresh Debian 12: builds a minimal Debian 12 root (debootstrap --variant=minbase,
# bookworm with its updates and security suites, as a fresh install has them), clones the committed tree
# into it (nothing uncommitted, nothing ignored) with ../shared beside it, and runs the
# two quick-start commands there exactly as the README gives them, as root, one after the other. Prints
# each command's exit status and the tail of its output; exits 0 only when both exit 0.
#
# Run it whenever tools/setup-debian.sh's package list or the build's dependencies change: a machine that
# already has a package hides a missing install step (CI runs on such a machine).
#
#   sudo bash tools/fresh-check.sh [--root DIR] [--keep] [--ccache DIR] [--only demo|test]
#     --root DIR    where the fresh root is made (default /var/tmp/projbot-fresh; it must not exist, or hold
#                   an earlier fresh root made by this script: then it is removed first)
#     --keep        keep the root afterwards (logs in DIR/work/*.log), for a look inside
#     --ccache DIR  share a compiler cache with the root (bind-mounted): faster, and no package comes with it
#     --only WHICH  run one of the two commands
# Needs root (debootstrap, chroot, mounts), debootstrap (installed when missing) and Debian's archive.
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$PWD
root=/var/tmp/projbot-fresh
keep=0
ccache_dir=
only=
usage() { sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//'; exit 2; }
while (($#)); do
  case $1 in
    --root) root=${2:?--root needs a folder}; shift 2 ;;
    --keep) keep=1; shift ;;
    --ccache) ccache_dir=${2:?--ccache needs a folder}; shift 2 ;;
    --only) only=${2:?--only needs demo or test}; [[ $only == demo || $only == test ]] || usage; shift 2 ;;
    -h|--help) usage ;;
    *) echo "fresh-check: unknown argument '$1'" >&2; usage ;;
  esac
done
[[ $(id -u) -eq 0 ]] || { echo "fresh-check: needs root (debootstrap, chroot and mounts)" >&2; exit 2; }
[[ -d ../shared/data ]] || { echo "fresh-check: ../shared/data is missing beside the project" >&2; exit 2; }
marker=.projbot-fresh-root
if [[ -e $root ]]; then
  # Never empty a folder that is not ours: only a root this script made (its marker) is replaced.
  [[ -f $root/$marker ]] || { echo "fresh-check: $root exists and is not a fresh root made by this script; choose --root" >&2; exit 2; }
fi
command -v debootstrap >/dev/null || { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq debootstrap >/dev/null; }

mounts=()
cleanup() {
  local m
  for ((i = ${#mounts[@]} - 1; i >= 0; i--)); do m=${mounts[i]}; umount -l "$m" 2>/dev/null || true; done
  if ((keep == 0)) && [[ -f $root/$marker ]]; then rm -rf --one-file-system "$root"; fi
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

# Whatever an earlier run left mounted inside (a killed run) goes first.
if [[ -d $root ]]; then
  { grep -o " $root/[^ ]*" /proc/mounts || true; } | sort -r | while read -r m; do umount -l "$m" || true; done
  rm -rf --one-file-system "$root"
fi
echo "fresh-check: debootstrap bookworm (minbase) into $root"
mkdir -p "$root"
debootstrap --variant=minbase bookworm "$root" http://deb.debian.org/debian >"$root.debootstrap.log" 2>&1 ||
  { tail -20 "$root.debootstrap.log"; echo "fresh-check: debootstrap failed"; exit 1; }
touch "$root/$marker"
rm -f "$root.debootstrap.log"
cat >"$root/etc/apt/sources.list" <<'EOF'
deb http://deb.debian.org/debian bookworm main
deb http://deb.debian.org/debian bookworm-updates main
deb http://deb.debian.org/debian-security bookworm-security main
EOF
cp /etc/resolv.conf "$root/etc/resolv.conf" 2>/dev/null || true

# A clone of the committed tree (as CI's), and ../shared beside it.
mkdir -p "$root/work/shared"
git clone -q "$repo" "$root/work/projbot"
cp -a "$repo/../shared/." "$root/work/shared/"

for m in proc sys dev dev/pts; do
  mkdir -p "$root/$m"
  mount --bind "/$m" "$root/$m"
  mounts+=("$root/$m")
done
if [[ -n $ccache_dir ]]; then
  mkdir -p "$ccache_dir" "$root/root/.cache/ccache"
  mount --bind "$ccache_dir" "$root/root/.cache/ccache"
  mounts+=("$root/root/.cache/ccache")
fi

# The README's quick start, as written there (the first block of its "Quick start" section).
mapfile -t commands < <(awk '/^## Quick start/{q=1} q&&/^```sh/{c=1; next} c&&/^```/{exit} c' "$repo/README.md" | sed 's/ *#.*$//' | sed '/^$/d')
((${#commands[@]} == 2)) || { echo "fresh-check: expected two commands in the README's quick start, found ${#commands[@]}" >&2; exit 1; }
status=0
for i in 0 1; do
  cmd=${commands[i]}
  [[ -n $only && $cmd != *"$only"* ]] && continue
  log=$root/work/quickstart-$((i + 1)).log
  echo "fresh-check: running '$cmd' in the fresh root"
  start=$(date +%s)
  rc=0
  chroot "$root" /usr/bin/env -i HOME=/root PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin LANG=C.UTF-8 \
    bash -c "cd /work/projbot && $cmd" >"$log" 2>&1 || rc=$?
  echo "----- tail of '$cmd' -----"
  tail -25 "$log"
  echo "fresh-check: '$cmd' exited $rc after $(($(date +%s) - start)) s"
  ((rc == 0)) || status=1
done
((keep)) && echo "fresh-check: the root is kept at $root (logs: $root/work/quickstart-*.log)"
exit "$status"
