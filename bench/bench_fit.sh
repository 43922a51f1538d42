#!/usr/bin/env bash
# The fit of issue 27 measured: per model, 100k area samples, decompose, the levels at <= 400 and
# <= 100 primitives (build --primitives; with --normals when NORMALS=1), `amgsplat fit` against the
# mesh timed on THREADS threads (the speed goal: 400 primitives, 64 views at 128 px, <= 60 s on 2
# cores), then bench_fit's table: SSIM against the mesh render on 16 held-out views at 128 and 256 px
# for the unfitted level, the fitted level and the meshoptimizer mesh of the same triangle count.
# Timings never decide pass or fail (STYLE.md 11).
#
#   bench/bench_fit.sh BUILD_DIR [MODELS="stanford-bunny cow"] [NORMALS=0] [THREADS=2] [OUT=mktemp]
# Environment: PRIMS (default "400 100"), FIT_ARGS (more fit options, e.g. "--bytes 30000" for the
# equal-bytes rows of issue 27; the fit stores BC3 atlases unless --uncompressed).
set -euo pipefail
build=${1:?build directory}; models=${2:-stanford-bunny cow}; normals=${3:-0}; threads=${4:-2}
out=${5:-$(mktemp -d)}
data=${ASP_TEST_DATA:-$(dirname "$0")/../../shared/data}
bin=$build/amgsplat
mkdir -p "$out/png"
echo "load: $(uptime)"
nflag=()
[ "$normals" = 1 ] && nflag=(--normals)
for m in $models; do
  mesh=$data/$m.obj
  "$bin" sample "$mesh" -o "$out/$m.ply" --points 100000 --quiet
  "$bin" decompose "$out/$m.ply" -o "$out/$m.amg" --quiet
  for p in ${PRIMS:-400 100}; do
    "$bin" build "$out/$m.amg" -o "$out/$m-$p.dps" --primitives "$p" "${nflag[@]}" --quiet >/dev/null
    t0=$(date +%s.%N)
    "$bin" fit "$out/$m-$p.dps" -o "$out/$m-$p-fit.dps" --reference "$mesh" --threads "$threads" --quiet ${FIT_ARGS:-}
    t1=$(date +%s.%N)
    echo "fit $m <= $p primitives: $(echo "$t1 - $t0" | bc) s wall on $threads threads"
    "$build/bench_fit" "$mesh" "$out/$m-$p.dps" "$out/$m-$p-fit.dps" 16 "$out/png"
  done
done
echo "files in $out"
