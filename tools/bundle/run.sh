#!/bin/sh
# Runs the bundle's projbot (tools/bundle.sh) on the libraries in lib/ (the library path: the executable's
# RPATH does not reach a library that names its own RUNPATH, as Cyclone DDS's does), adding what depends
# on the machine:
# - libstdc++ and libgcc_s from lib/fallback where the machine's are missing or older than the build's;
# - the NVIDIA driver's Vulkan ICD where the loader's usual folders have none (a container that mounts the
#   driver under /usr/local/nvidia);
# - the validation layer carried in layers/ (bundle.sh --with-validation), for `--validation`;
# - the shipped scenes and models (PROJBOT_ASSETS).
# Usage: DIR/run.sh COMMAND [options]   (DIR/run.sh --help lists the commands)
here=$(cd "$(dirname "$0")" && pwd)

# The libraries bundle.sh packed (lib/packed.tar.xz), unpacked once, beside the others.
if [ -f "$here/lib/packed.tar.xz" ] && [ ! -f "$here/lib/.unpacked" ]; then
  tmp=$(mktemp -d "$here/lib/.unpack.XXXXXX" 2>/dev/null) || {
    echo "run.sh: cannot write in $here/lib to unpack its libraries: make the folder writable for the first run" >&2
    exit 1
  }
  if command -v xz >/dev/null 2>&1; then
    xz -dc "$here/lib/packed.tar.xz" | tar -C "$tmp" -xf -
  else
    python3 -c 'import sys, tarfile; tarfile.open(sys.argv[1]).extractall(sys.argv[2])' "$here/lib/packed.tar.xz" "$tmp"
  fi || { rm -rf "$tmp"; echo "run.sh: could not unpack $here/lib/packed.tar.xz (damaged in the copy? carry the bundle again; unpacking needs xz or python3)" >&2; exit 1; }
  mv "$tmp"/* "$here/lib/" && rmdir "$tmp" && : >"$here/lib/.unpacked"
fi

libs=$here/lib
need=$(cat "$here/lib/fallback/NEEDS" 2>/dev/null)
system_cxx=$(ldconfig -p 2>/dev/null | awk '/libstdc\+\+\.so\.6 .*x86-64/ { print $NF; exit }')
if [ -z "$system_cxx" ] || { [ -n "$need" ] && ! grep -qa "$need" "$system_cxx"; }; then
  libs=$libs:$here/lib/fallback
fi
LD_LIBRARY_PATH="$libs${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
export LD_LIBRARY_PATH

if [ -z "$VK_DRIVER_FILES$VK_ICD_FILENAMES" ] && ! ls /usr/share/vulkan/icd.d/*.json /etc/vulkan/icd.d/*.json \
  /usr/local/share/vulkan/icd.d/*.json >/dev/null 2>&1; then
  for icd in /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json /usr/local/nvidia/icd.d/nvidia_icd.json; do
    if [ -f "$icd" ]; then
      VK_DRIVER_FILES=$icd VK_ICD_FILENAMES=$icd
      export VK_DRIVER_FILES VK_ICD_FILENAMES
      break
    fi
  done
fi

if [ -d "$here/layers" ]; then
  VK_ADD_LAYER_PATH="$here/layers${VK_ADD_LAYER_PATH:+:$VK_ADD_LAYER_PATH}"
  export VK_ADD_LAYER_PATH
fi
PROJBOT_ASSETS=${PROJBOT_ASSETS:-$here/assets}
export PROJBOT_ASSETS
exec "$here/projbot" "$@"
