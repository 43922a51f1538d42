#!/bin/bash
# The compute-renderer benchmark on an NVIDIA machine (issue 28; bench/gpu/README.md): run from the
# repository root after scripts/pack_gpu_bench.sh filled .gpubench/. Prints the card (nvidia-smi),
# the EGL vendor file and the GL vendor/renderer that drew (must say NVIDIA), then bench_compute at
# 1M, 10M and 100M points, 1024x1024; everything goes to $OUT/gpu_bench.txt (or /tmp without OUT).
# Environment: POINTS (1e6,1e7,1e8), SIZE (1024), FRAMES (9), SPLAT_MAX (1e7), LIMIT_S (240).
set -u
pk=.gpubench
out=${OUT:-/tmp/gpu_bench_out}
mkdir -p "$out"
log=$out/gpu_bench.txt
if [ ! -x "$pk/bench_compute" ]; then
    echo "run_gpu_bench: $pk/bench_compute missing: run scripts/pack_gpu_bench.sh and carry .gpubench" | tee "$log"
    exit 1
fi
{
    date -u
    echo "== card"
    nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader 2>&1 || echo "no nvidia-smi (no NVIDIA driver here)"
    # glvnd picks the EGL vendor from a JSON file; the NVIDIA container images put it beside the driver
    if [ -z "${__EGL_VENDOR_LIBRARY_FILENAMES:-}" ]; then
        for f in /usr/share/glvnd/egl_vendor.d/10_nvidia.json /etc/glvnd/egl_vendor.d/10_nvidia.json \
            /usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json; do
            if [ -f "$f" ]; then
                export __EGL_VENDOR_LIBRARY_FILENAMES=$f
                break
            fi
        done
    fi
    echo "== EGL vendor file: ${__EGL_VENDOR_LIBRARY_FILENAMES:-glvnd default search (/usr/share/glvnd/egl_vendor.d)}"
    libpath=$pk/lib:$pk/gl
    for d in /usr/local/nvidia/lib64 /usr/local/nvidia/lib /usr/lib/x86_64-linux-gnu /usr/lib64; do
        [ -d "$d" ] && libpath=$libpath:$d
    done
    echo "== library path: $libpath"
    # where the driver's EGL pieces are, for a run that does not reach NVIDIA
    echo "== EGL vendor files: $(ls /usr/share/glvnd/egl_vendor.d /etc/glvnd/egl_vendor.d \
        /usr/local/nvidia/share/glvnd/egl_vendor.d 2>/dev/null | tr '\n' ' ')"
    echo "== libEGL_nvidia: $( (ldconfig -p 2>/dev/null | grep -o '/[^ ]*libEGL_nvidia[^ ]*'; ls /usr/local/nvidia/lib64/libEGL_nvidia* 2>/dev/null) | sort -u | tr '\n' ' ')"
    echo "== bench_compute ${POINTS:-1e6,1e7,1e8} ${SIZE:-1024} ${FRAMES:-9} ${SPLAT_MAX:-1e7}"
    timeout "${LIMIT_S:-240}" "$pk/ld-linux-x86-64.so.2" --library-path "$libpath" "$pk/bench_compute" \
        "${POINTS:-1e6,1e7,1e8}" "${SIZE:-1024}" "${FRAMES:-9}" "${SPLAT_MAX:-1e7}"
    echo "== exit status $?"
} 2>&1 | tee "$log"
if grep -q "GL_VENDOR NVIDIA" "$log"; then
    echo "run_gpu_bench: drawn on NVIDIA" | tee -a "$log"
else
    echo "run_gpu_bench: WARNING: GL_VENDOR is not NVIDIA (see above)" | tee -a "$log"
fi
