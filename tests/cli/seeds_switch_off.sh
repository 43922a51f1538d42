#!/usr/bin/env bash
# Issue 17, the rest: a preset's flags can be switched off by hand (--no-overlap-backfaces,
# --no-normalise-color), and render's debug drawings of the thesis viewer (appendix C: eigenvectors,
# texel midpoints, the affine triangulation, one picked domain only) draw their colours where expected.
source "$(dirname "$0")/common.sh"
A="$AMGSPLAT"
mpi_asan="${ASAN_OPTIONS:-}:fast_unwind_on_malloc=0" # decompose/build start MPI (see seeds_render.sh)
jget() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(eval(sys.argv[2]))" "$@"; }
# has FILE R,G,B MIN: at least MIN pixels of exactly that colour (MIN 0: none at all)
has() {
  local e="sum(px(x, y)[:3] == ($2) for x in range(w) for y in range(h))"
  if [[ $3 == 0 ]]; then python3 "$(dirname "$0")/png_check.py" "$1" "$e == 0"
  else python3 "$(dirname "$0")/png_check.py" "$1" "$e >= $3"; fi
}

# --no-overlap-backfaces after --preset journal: the pixels of the journal's options without that flag.
# An open sheet folded at x = 0 whose second face turns its back at azimuth 40 (seeds_render.sh).
python3 - "$T/fold.ply" <<'PY'
import math, sys
rows = []
for j in range(41):
    y = -0.4 + 0.02 * j
    rows += ["%g %g 0 0 0 1" % (-1 + 0.025 * i, y) for i in range(41)]
    rows += ["%g %g %g %g 0 %g" % (0.025 * i, y, 0.05 * i, -2 / math.sqrt(5), 1 / math.sqrt(5)) for i in range(1, 25)]
open(sys.argv[1], "w").write("ply\nformat ascii 1.0\nelement vertex %d\n" % len(rows) + "".join(
    "property float %s\n" % n for n in ("x", "y", "z", "nx", "ny", "nz")) + "end_header\n" + "\n".join(rows) + "\n")
PY
ASAN_OPTIONS="$mpi_asan" "$A" decompose "$T/fold.ply" -o "$T/fold.amg" --crease-cut -1 -q
ASAN_OPTIONS="$mpi_asan" "$A" build "$T/fold.amg" -o "$T/fold.dps" --primitives 4 --neighbours 0.001 -q >/dev/null
V=(--view 40,0 --size 96x96 --transparent -q)
"$A" render "$T/fold.dps" -o "$T/pj.png" --preset journal "${V[@]}"
"$A" render "$T/fold.dps" -o "$T/pn.png" --preset journal --no-overlap-backfaces "${V[@]}"
"$A" render "$T/fold.dps" -o "$T/hb.png" --method overlap --crease-angle off --overlap-backfaces "${V[@]}"
"$A" render "$T/fold.dps" -o "$T/hn.png" --method overlap --crease-angle off "${V[@]}"
cmp -s "$T/pj.png" "$T/hb.png" || fail "--preset journal differs from its options by hand"
cmp -s "$T/pn.png" "$T/hn.png" || fail "--preset journal --no-overlap-backfaces still draws back faces"
! cmp -s "$T/pn.png" "$T/pj.png" || fail "--no-overlap-backfaces changed nothing: the fold shows no back face"
# ... before or after the preset
"$A" render "$T/fold.dps" -o "$T/pm.png" --no-overlap-backfaces --preset journal "${V[@]}"
cmp -s "$T/pm.png" "$T/hn.png" || fail "--no-overlap-backfaces before --preset lost"
expect_fail 2 "exclude each other" "$A" render "$T/fold.dps" -o "$T/x.png" --overlap-backfaces --no-overlap-backfaces

# --no-normalise-color after --preset thesis: the thesis's atlas with colour divided by f
"$A" synth sphere --points 1500 -o "$T/s.ply" -q
ASAN_OPTIONS="$mpi_asan" "$A" decompose "$T/s.ply" -o "$T/s.amg" -q
B=(--level L-2 -q)
ASAN_OPTIONS="$mpi_asan" "$A" build "$T/s.amg" -o "$T/t.dps" --preset thesis --atlas "$T/t.png" "${B[@]}" >/dev/null
ASAN_OPTIONS="$mpi_asan" "$A" build "$T/s.amg" -o "$T/tn.dps" --preset thesis --no-normalise-color --atlas "$T/tn.png" "${B[@]}" >/dev/null
ASAN_OPTIONS="$mpi_asan" "$A" build "$T/s.amg" -o "$T/th.dps" --tau 0.01 --method radial --normalise ge1 --atlas "$T/th.png" "${B[@]}" >/dev/null
cmp -s "$T/tn.png" "$T/th.png" || fail "--preset thesis --no-normalise-color is not the thesis's options without it"
! cmp -s "$T/tn.png" "$T/t.png" || fail "--no-normalise-color changed nothing"
ASAN_OPTIONS="$mpi_asan" expect_fail 2 "exclude each other" "$A" build "$T/s.amg" -o "$T/x.dps" --normalise-color --no-normalise-color

# debug drawings on grey primitives (--no-model-colors: grey 200, so the debug colours stand alone)
ASAN_OPTIONS="$mpi_asan" "$A" build "$T/s.amg" -o "$T/g.dps" --level L-2 --no-model-colors -q >/dev/null
R=(--size 128x128 --view 30,20 --unlit --samples 1 -q)
"$A" render "$T/g.dps" -o "$T/g0.png" "${R[@]}"
"$A" render "$T/g.dps" -o "$T/ge.png" --debug eigenvectors "${R[@]}"
"$A" render "$T/g.dps" -o "$T/gt.png" --debug texels "${R[@]}"
"$A" render "$T/g.dps" -o "$T/gb.png" --debug texels,eigenvectors "${R[@]}"
for c in 255,0,0 0,255,0 255,0,255; do
  has "$T/g0.png" $c 0 || fail "colour $c without --debug"
done
has "$T/ge.png" 255,0,0 50 && has "$T/ge.png" 0,255,0 50 || fail "no eigenvector lines"
has "$T/ge.png" 255,0,255 0 || fail "texel dots without --debug texels"
has "$T/gt.png" 255,0,255 500 || fail "no texel midpoints"
has "$T/gb.png" 255,0,255 500 && has "$T/gb.png" 255,0,0 50 || fail "--debug texels,eigenvectors"
# the affine triangulation (made again from the .amg the file names), cyan
# it starts MPI and draws: LeakSanitizer at exit hangs there with full unwinding, so no leak check (as cli.eval)
ASAN_OPTIONS="${ASAN_OPTIONS:-}:detect_leaks=0" "$A" render "$T/g.dps" -o "$T/gd.png" --debug triangulation "${R[@]}"
has "$T/gd.png" 0,255,255 200 || fail "no triangulation lines"
has "$T/g0.png" 0,255,255 0 && has "$T/gd.png" 255,0,255 0 || fail "cyan without --debug triangulation, or texels with it"
ASAN_OPTIONS="$mpi_asan" "$A" build "$T/s.ply" -o "$T/p.dps" --level L-2 -q >/dev/null
ASAN_OPTIONS="${ASAN_OPTIONS:-}:detect_leaks=0" expect_fail 1 "needs the .amg" "$A" render "$T/p.dps" -o "$T/x.png" --debug triangulation
expect_fail 2 "--debug expects eigenvectors, texels" "$A" render "$T/g.dps" -o "$T/x.png" --debug normals
expect_fail 2 "need a .dps input" "$A" render "$T/s.ply" -o "$T/x.png" --debug texels
# one picked domain: every domain's pixels lie inside the full silhouette (those facing away draw
# none: back faces are culled), and together the domains cover it
n=$(jget <("$A" info "$T/g.dps" --json) "d['levels'][0]['primitives']")
"$A" render "$T/g.dps" -o "$T/ga.png" --transparent "${R[@]}"
for ((k = 0; k < n; k++)); do
  "$A" render "$T/g.dps" -o "$T/g1.png" --only-domain $k --transparent "${R[@]}"
  "$A" imgdiff "$T/g1.png" "$T/ga.png" --json >"$T/one-$k.json"
done
python3 - "$T" "$n" <<'PY' || fail "--only-domain"
import json, sys
t, n, some = sys.argv[1], int(sys.argv[2]), 0
for k in range(n):
    d = json.load(open("%s/one-%d.json" % (t, k)))
    a, b = d["silhouette"][0]["pixels"], d["silhouette"][1]["pixels"]
    assert a <= b and (a == 0 or abs(d["iou"] - a / b) < 0.01), (k, a, b, d["iou"])
    some += 0 < a < 0.5 * b
assert some >= 2, some
PY
expect_fail 1 "no domain $n" "$A" render "$T/g.dps" -o "$T/x.png" --only-domain "$n"
