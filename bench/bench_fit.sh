#!/usr/bin/env bash
# The fit of issue 27 measured: per model, 100k area samples, decompose, the levels nearest 400 and
# 100 primitives (build --primitives; with --normals when NORMALS=1), `amgsplat fit` against the
# mesh timed on THREADS threads (the speed goal: 400 primitives, 64 views at 128 px, <= 60 s on 2
# cores), the Poisson peer (bench/poisson_peer.py, Debian's python3-open3d: screened Poisson of the
# same samples decimated to each level's primitive count, timed), then bench_fit's table: SSIM
# against the mesh render on 16 held-out views at 128 and 256 px for the unfitted level, the fitted
# level, the meshoptimizer mesh of the same triangle count, the Poisson peer, and the meshoptimizer
# mesh at the fitted level's GPU bytes (textured meshes: texture and triangles sharing the bytes).
# Timings never decide pass or fail (STYLE.md 11).
#
#   bench/bench_fit.sh BUILD_DIR [MODELS="stanford-bunny cow"] [NORMALS=0] [THREADS=2] [OUT=mktemp]
# MODELS: names of ASP_TEST_DATA's OBJ files; "spot" is spot_triangulated.obj with spot_texture.png.
# Environment:
#   PRIMS          levels by count (default "400 100"; build --primitives N)
#   LEVELS         levels by name instead, one .dps each (e.g. "L-4 L-3 L-2 L-1 L": build --level);
#                  "le:N" = every level of the model's decomposition with at most N primitives
#   FIT_ARGS       more fit options (e.g. "--iterations 120")
#   BYTES_PER_PRIM a budget per level of that many GPU bytes a primitive (fit --bytes prims * X),
#                  one run per value (e.g. "300 450"): the equal-bytes rows of issue 27; a budget
#                  below 4x4 texels a primitive is raised to the least the fit accepts
#   POISSON        0 skips the Poisson peer (default: on where /usr/bin/python3 imports open3d)
# Lines starting "run," name the run (model, level, primitives, budget, fit seconds); the CSV lines
# after them are bench_fit's.
set -euo pipefail
build=${1:?build directory}; models=${2:-stanford-bunny cow}; normals=${3:-0}; threads=${4:-2}
out=${5:-$(mktemp -d)}
here=$(cd "$(dirname "$0")" && pwd)
data=${ASP_TEST_DATA:-$here/../../shared/data}
bin=$build/amgsplat
py=/usr/bin/python3 # Debian's python3-open3d lives in the system interpreter
mkdir -p "$out/png"
echo "load: $(uptime)"
nflag=()
[ "$normals" = 1 ] && nflag=(--normals)
poisson=${POISSON:-1}
if [ "$poisson" = 1 ] && ! "$py" -c 'import open3d' 2>/dev/null; then
  echo "bench_fit.sh: no python3-open3d (scripts/bootstrap.sh --bench installs it): Poisson column skipped" >&2
  poisson=0
fi
prims_of() { # the primitive count of a .dps's one level
  "$bin" info --json "$1" | "$py" -c 'import json,sys; print(json.load(sys.stdin)["levels"][0]["primitives"])'
}
for m in $models; do
  mesh=$data/$m.obj; tex=(); btex=()
  if [ "$m" = spot ]; then
    mesh=$data/spot_triangulated.obj; tex=(--texture "$data/spot_texture.png"); btex=(--texture "$data/spot_texture.png")
  fi
  "$bin" sample "$mesh" "${tex[@]}" -o "$out/$m.ply" --points 100000 --quiet
  "$bin" decompose "$out/$m.ply" -o "$out/$m.amg" --quiet
  sel=(); names=()
  levels=${LEVELS:-}
  if [[ $levels == le:* ]]; then
    levels=$("$bin" info --json "$out/$m.amg" | "$py" -c 'import json,sys
print(" ".join(l["name"] for l in json.load(sys.stdin)["levels"] if l["unknowns"] <= int(sys.argv[1])))' "${levels#le:}")
  fi
  if [ -n "$levels" ]; then
    for l in $levels; do sel+=("--level $l"); names+=("$l"); done
  else
    for p in ${PRIMS:-400 100}; do sel+=("--primitives $p"); names+=("p$p"); done
  fi
  counts=()
  for i in "${!sel[@]}"; do
    # shellcheck disable=SC2086 # "--level L-4" is two words
    "$bin" build "$out/$m.amg" -o "$out/$m-${names[$i]}.dps" ${sel[$i]} "${nflag[@]}" --quiet >/dev/null
    counts+=("$(prims_of "$out/$m-${names[$i]}.dps")")
  done
  pre=()
  if [ "$poisson" = 1 ]; then
    echo "poisson,$m: count,triangles,vertices,poisson_s,decimate_s"
    # shellcheck disable=SC2046 # one count a word
    "$py" "$here/poisson_peer.py" "$out/$m.ply" "$out/$m-poisson" $(printf '%s\n' "${counts[@]}" | sort -un) |
      sed "s/^/poisson,$m,/"
    pre=(--poisson "$out/$m-poisson")
  fi
  for i in "${!sel[@]}"; do
    n=${names[$i]}; c=${counts[$i]}
    for x in ${BYTES_PER_PRIM:-none}; do
      budget=(); tag=$n
      if [ "$x" != none ]; then budget=(--bytes $((c * x))); tag=$n-b$x; fi
      t0=$(date +%s.%N)
      # shellcheck disable=SC2086 # FIT_ARGS is a list of options
      fit() {
        # shellcheck disable=SC2086 # FIT_ARGS is a list of options
        "$bin" fit "$out/$m-$n.dps" -o "$out/$m-$tag-fit.dps" --reference "$mesh" "${tex[@]}" \
          --threads "$threads" --quiet "$@" ${FIT_ARGS:-} 2>"$out/fit.err" >/dev/null
      }
      if ! fit "${budget[@]}"; then
        # a budget below 4x4 texels a primitive: the least one the fit accepts, which it names
        least=$(sed -n 's/.*4x4 texels take (\([0-9]*\)).*/\1/p' "$out/fit.err")
        if [ -z "$least" ] || ! budget=(--bytes "$least") || ! fit "${budget[@]}"; then
          echo "run,$m,$n,$c,${budget[1]:-none},failed: $(cat "$out/fit.err")"
          continue
        fi
      fi
      t1=$(date +%s.%N)
      echo "run,$m,$n,$c,${budget[1]:-none},$(echo "$t1 - $t0" | bc)"
      mkdir -p "$out/png/$tag"
      "$build/bench_fit" "$mesh" "$out/$m-$n.dps" "$out/$m-$tag-fit.dps" 16 "$out/png/$tag" "${btex[@]}" "${pre[@]}"
    done
  done
done
echo "files in $out"
