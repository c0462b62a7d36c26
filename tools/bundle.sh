#!/usr/bin/env bash
# A self-contained folder that carries projbot to a machine without this build's Debian libraries (an
# NVIDIA GPU machine, issue 45): the portable build (CMake preset `bundle`: no MRPT, OpenCV, FFmpeg or
# PCL io; what needs them says so when called), stripped, with every library it loads beyond the base.
#
#   bash tools/bundle.sh DIR
#
# The base, not carried: glibc 2.36 or newer (libc, libm, ld-linux), and the GPU's driver with its Vulkan
# ICD file. Carried: everything else the executable loads, the Vulkan loader and the Khronos validation
# layer (for --validation) included, in DIR/lib, which the executable's RPATH names ($ORIGIN/lib); those
# over 1 MiB packed with xz (lib/packed.tar.xz), which DIR/run.sh unpacks on its first run (the folder must
# be writable then). libstdc++ and libgcc_s go to DIR/lib/fallback, used only where the machine's own are
# missing or older than the build's (DIR/run.sh decides).
#
# DIR must be new, empty or an earlier bundle (it holds .projbot-bundle): anything else is refused before
# the build. The folder is made beside it and moved into place at the end. Prints the folder's size last.
set -euo pipefail
cd "$(dirname "$0")/.."

usage() { echo "usage: bash tools/bundle.sh DIR" >&2; exit 2; }
out=""
for a in "$@"; do
  case "$a" in
    -h | --help) sed -n '2,16p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "bundle: unknown option '$a'" >&2; usage ;;
    *) [[ -z "$out" ]] || { echo "bundle: one folder, got '$out' and '$a'" >&2; usage; }; out="$a" ;;
  esac
done
[[ -n "$out" ]] || usage
out="$(realpath -m "$out")"
case "$out" in "$PWD" | "$PWD"/build | "$PWD"/build/* | / ) echo "bundle: $out is not a folder to fill; name a new one" >&2; exit 2 ;; esac
if [[ -e "$out" && ! -d "$out" ]]; then echo "bundle: $out exists and is not a folder" >&2; exit 2; fi
if [[ -d "$out" && -n "$(ls -A "$out")" && ! -f "$out/.projbot-bundle" ]]; then
  echo "bundle: $out holds files that are not a bundle; name a new or empty folder" >&2
  exit 2
fi
mkdir -p "$(dirname "$out")"
[[ -w "$(dirname "$out")" ]] || { echo "bundle: cannot write in $(dirname "$out")" >&2; exit 2; }

bash tools/setup-debian.sh
export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=true
cmake --preset bundle >/dev/null
cmake --build --preset bundle

work="$(mktemp -d "$(dirname "$out")/.bundle.XXXXXX")"
chmod 755 "$work"
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/lib/fallback"
mib() { awk -v b="$1" 'BEGIN { printf "%.1f", b / 1048576 }'; }
size_of() { du -sbL "$@" | awk '{ s += $1 } END { print s + 0 }'; }

# The executable and what stripping saves.
cp build/bundle/tools/projbot "$work/projbot"
before=$(size_of "$work/projbot")
strip --strip-unneeded "$work/projbot"
echo "bundle: projbot $(mib "$before") MiB, stripped $(mib "$(size_of "$work/projbot")") MiB"

# Its libraries: ldd's closure less the base; libstdc++ and libgcc_s as the fallback.
deps=$(ldd "$work/projbot")
if grep -q "not found" <<<"$deps"; then
  grep "not found" <<<"$deps" >&2
  echo "bundle: the executable needs libraries this machine does not have" >&2
  exit 1
fi
base_re='^(linux-vdso\.so|ld-linux-x86-64\.so|libc\.so|libm\.so|libpthread\.so|libdl\.so|librt\.so|libresolv\.so|libutil\.so)'
awk '$2 == "=>" && $3 ~ /^\// { print $1, $3 }' <<<"$deps" | while read -r soname path; do
  [[ "$soname" =~ $base_re ]] && continue
  case "$soname" in
    libstdc++.so.* | libgcc_s.so.*) cp -L "$path" "$work/lib/fallback/$soname" ;;
    *) cp -L "$path" "$work/lib/$soname" ;;
  esac
done
# The Vulkan loader: the engine opens it at run time (dlopen), so ldd does not list it.
cp -L "$(ldconfig -p | awk '/libvulkan\.so\.1 .*x86-64/ { print $NF; exit }')" "$work/lib/libvulkan.so.1"
# The Khronos validation layer, for `--validation` (packed with the libraries below).
cp -L /usr/lib/x86_64-linux-gnu/libVkLayer_khronos_validation.so "$work/lib/"
mkdir -p "$work/layers"
sed 's#"library_path": *"[^"]*"#"library_path": "../lib/libVkLayer_khronos_validation.so"#' \
  /usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json >"$work/layers/VkLayer_khronos_validation.json"

# The newest libstdc++ symbol version anything carried asks for: run.sh uses the fallback where the machine's
# libstdc++ lacks it.
objdump -T "$work/projbot" "$work"/lib/*.so* 2>/dev/null | grep -o 'GLIBCXX_[0-9.]*' | sort -uV | tail -1 \
  >"$work/lib/fallback/NEEDS"
glibc=$(objdump -T "$work/projbot" "$work"/lib/*.so* "$work"/lib/fallback/*.so* 2>/dev/null | grep -o 'GLIBC_[0-9.]*' | sort -uV | tail -1)
raw=$(size_of "$work/lib")
echo "bundle: $(ls "$work/lib" | grep -c '\.so') libraries, $(mib "$raw") MiB; the base must have ${glibc/_/ } or newer"

# The large libraries (PCL's explicit instantiations for every point type above all) packed with xz: a tenth
# of their size. run.sh unpacks them into lib/ on its first run.
big=$(cd "$work/lib" && find . -maxdepth 1 -name '*.so*' -size +1M -printf '%f\n' | sort)
if [[ -n "$big" ]]; then
  (cd "$work/lib" && tar -cf - $big | xz -9 -T0 >packed.tar.xz && rm -f $big)
  echo "bundle: packed $(echo "$big" | wc -l) libraries over 1 MiB: $(mib "$raw") -> $(mib "$(size_of "$work/lib")") MiB"
fi

# The shipped scenes, models and sites (the executable finds them through PROJBOT_ASSETS).
mkdir -p "$work/assets"
cp -r assets/models assets/scenes assets/sites "$work/assets/"
cp tools/bundle/run.sh tools/bundle/bench.sh "$work/"
chmod +x "$work/run.sh" "$work/bench.sh"
git log -1 --format='projbot %H (%cd)' >"$work/.projbot-bundle" 2>/dev/null || echo projbot >"$work/.projbot-bundle"

# Into place: an earlier bundle is replaced only now, whole.
if [[ -d "$out" ]]; then
  old="$(mktemp -d "$(dirname "$out")/.bundle-old.XXXXXX")"
  mv "$out" "$old/"
  mv "$work" "$out"
  rm -rf "$old"
else
  mv "$work" "$out"
fi
trap - EXIT
echo "bundle: $(mib "$(size_of "$out")") MiB in $out"
