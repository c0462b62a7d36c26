#!/usr/bin/env bash
# Installs the Debian 12 packages Projbot builds, tests and runs with, when they are missing.
# Safe to run again: it asks apt only for what dpkg does not already have.
set -euo pipefail

# Every package is named: the script installs without recommends, so nothing may come in as one (clang's
# sanitizer and libFuzzer runtimes are libclang-rt-14-dev, not clang). After changing this list, run
# tools/fresh-check.sh (the quick start on a fresh Debian 12 root).
packages=(
  build-essential cmake ninja-build ccache pkg-config git ca-certificates
  clang libclang-rt-14-dev clang-format
  libvulkan-dev vulkan-validationlayers mesa-vulkan-drivers glslang-tools vulkan-tools
  libglm-dev libeigen3-dev libtinygltf-dev libstb-dev nlohmann-json3-dev
  libglfw3-dev libyaml-cpp-dev libgtest-dev libgmock-dev libbenchmark-dev
  libpcl-dev libopenni2-dev libfreenect-dev libfreenect-bin cyclonedds-dev cyclonedds-tools libtiff-dev libboost-dev libmrpt-dev
  libopencv-dev libopencv-contrib-dev libassimp-dev libavformat-dev libavcodec-dev libswscale-dev libavutil-dev
  libcpp-httplib-dev liblo-dev chromium chromium-driver python3-selenium
  libx11-dev libxrandr-dev xvfb x11-apps xauth bc valgrind
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if ((${#missing[@]} == 0)); then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi

sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then
  command -v sudo >/dev/null || { echo "setup: not root and no sudo; install: ${missing[*]}" >&2; exit 1; }
  sudo_cmd=(sudo)
fi

echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
