#!/usr/bin/env bash
# The README's main command: installs dependencies, builds, and runs the whole
# pipeline on the default models — the Stanford bunny from Debian's
# glmark2-data and the synthetic octahedron of Reniers & Telea Fig. 1:
# sample -> render points -> AMG decomposition -> domain primitives ->
# render primitives -> evaluation table and chart. Results go to out/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/bootstrap.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build build -j "$(nproc)" --target amgsplat_cli
bin=build/amgsplat
mkdir -p out
bunny=/usr/share/glmark2/models/bunny.obj

step() { printf '\n== %s\n' "$*"; }

step "points: sample the bunny, make the octahedron, render both from 8 sides"
$bin synth octahedron --points 16000 -o out/octahedron.ply
$bin sample "$bunny" --method area --points 100000 -o out/bunny.ply
for m in octahedron bunny; do
  $bin render out/$m.ply --views 8 --size 256x256 -o out/$m-points.png
done

step "decompose: AMG multiscale of quasi-flat domains (journal section 2)"
$bin decompose out/bunny.ply -o out/bunny.amg --stats
$bin render out/bunny.amg --color-by classifier --views 4 --size 256x256 -o out/bunny-classifier.png
$bin render out/bunny.amg --color-by domains --level L-3 --views 4 --size 256x256 -o out/bunny-domains.png

step "build: one textured polygon per domain, level nearest 400 primitives (journal section 3)"
$bin build out/bunny.amg --primitives 400 -o out/bunny.dps --atlas out/bunny-atlas.png
$bin render out/bunny.dps --method prefix --views 8 --size 256x256 -o out/bunny-primitives.png

step "hybrid and scenes: points where primitives fail; 200 bunnies mixing AMG levels by view (issue 18)"
$bin render out/bunny.dps --hybrid --views 8 --size 256x256 -o out/bunny-hybrid.png
$bin build out/bunny.amg --level L-7..L -o out/bunny-levels.dps
$bin scene field out/bunny-levels.dps --instances 200 -o out/field.json
$bin render out/field.json --tolerance 2 --size 512x512 -o out/field.png

step "eval: primitives against the point set, every level up to 500 primitives"
$bin eval out/bunny.ply -o out/eval-bunny --views 8 --sizes 128 --max-primitives 500
echo
echo "demo: pictures and tables in out/ (bunny-points.png, bunny-primitives.png, bunny-hybrid.png, field.png, eval-bunny/ssim-128.png, eval-bunny/eval.csv)"
