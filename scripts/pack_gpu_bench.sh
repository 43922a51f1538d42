#!/bin/bash
# Packs bench_compute for a GPU machine without Debian's libraries (bench/gpu/README.md): the
# binary, every shared library ldd lists for it except the GL ones (libGL, libEGL, libGLX,
# libOpenGL, libGLdispatch: glvnd's dispatchers must reach the device's NVIDIA driver), and
# Debian's dynamic loader into .gpubench/, plus glvnd itself (libegl1 libglvnd0 libopengl0 libgl1
# libglx0 libgles2, apt-get download + dpkg -x) into .gpubench/gl. On the device it runs as
#   .gpubench/ld-linux-x86-64.so.2 --library-path .gpubench/lib:.gpubench/gl .gpubench/bench_compute
# whatever the device's glibc (bench/gpu/run_gpu_bench.sh does that).
# .gitignore ignores .gpubench/, so a device run carries it (carry: [".gpubench"]).
# usage: scripts/pack_gpu_bench.sh [BUILD_DIR=build]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
bin=$build/bench_compute
out=$root/.gpubench
if [ ! -x "$bin" ]; then
    echo "pack_gpu_bench: $bin is not built (cmake --build $build --target bench_compute)" >&2
    exit 1
fi
rm -rf "$out"
mkdir -p "$out/lib" "$out/gl"
cp "$bin" "$out/bench_compute"
strip --strip-debug "$out/bench_compute"
loader=$(ldd "$bin" | awk '/ld-linux-x86-64\.so/ {print $1; exit}')
cp -L "$loader" "$out/ld-linux-x86-64.so.2"
ldd "$bin" | awk '$2 == "=>" && $3 ~ /^\// {print $1, $3}' | while read -r name path; do
    case "$name" in
    libGL.so* | libEGL.so* | libGLX.so* | libOpenGL.so* | libGLdispatch.so* | libGLESv2.so* | ld-linux*) continue ;;
    esac
    cp -L "$path" "$out/lib/$name"
    strip --strip-unneeded "$out/lib/$name" 2>/dev/null || true
done
# glvnd: the dispatch libraries that load the vendor named by the device's egl_vendor.d JSON
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
(cd "$tmp" && apt-get download libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2 >/dev/null)
for deb in "$tmp"/*.deb; do
    dpkg -x "$deb" "$tmp/root"
done
cp -a "$tmp"/root/usr/lib/x86_64-linux-gnu/lib*.so* "$out/gl/"
# the run must not find this machine's Mesa: only glvnd and the device's vendor library
rm -f "$out"/lib/libEGL_mesa* "$out"/lib/libGLX_mesa*
cp "$root/bench/gpu/run_gpu_bench.sh" "$out/"
du -sh "$out"
echo "pack_gpu_bench: packed into $out"
