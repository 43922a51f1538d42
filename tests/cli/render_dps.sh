# amgsplat render on a .dps (domain primitives, journal section 4): every method draws the octahedron's
# 8 primitives, the options change the pixels they should, and bad options or files fail cleanly.
# Only the commands that start MPI (decompose, build) get the full stack unwinding that MPI's leak
# suppressions need under ASan (tests/lsan.supp); it would slow llvmpipe's renders 100-fold.
source "$(dirname "$0")/common.sh"


"$AMGSPLAT" synth octahedron -o "$T/o.ply" -q
mpi_asan="${ASAN_OPTIONS:-}:fast_unwind_on_malloc=0"
ASAN_OPTIONS="$mpi_asan" "$AMGSPLAT" decompose "$T/o.ply" -o "$T/o.amg" -q
ASAN_OPTIONS="$mpi_asan" "$AMGSPLAT" build "$T/o.amg" -o "$T/o.dps" --primitives 8 -q >/dev/null

# the default method (normalized) from +z: the centre is covered, the corners are not
"$AMGSPLAT" render "$T/o.dps" -o "$T/n.png" --size 48x48 --view 0,0 --transparent --json >"$T/json"
check "$T/n.png" "w == 48 and h == 48 and px(24, 24)[3] == 255 and px(0, 0)[3] == 0 and px(47, 47)[3] == 0"
python3 -c "
import json, sys
d = json.load(open(sys.argv[1]))
assert d['renderer'] == 'prim' and d['method'] == 'normalized' and d['points'] == 8 and d['primitives'] == 8, d
assert d['level'] > 5 and d['tolerance'] == 0, d  # the 8-domain level is among the coarsest
" "$T/json" || fail "json: $(cat "$T/json")"

# every method draws something where the octahedron is
for m in normalized prefix overlap two-pass dark-backface dark-backface-soft blend-all no-blend polygons; do
  "$AMGSPLAT" render "$T/o.dps" -o "$T/$m.png" --size 48x48 --view 30,20 --method "$m" -q
  check "$T/$m.png" "px(24, 24)[:3] != (255, 255, 255) and px(0, 0) == (255, 255, 255, 255)"
done

# crease clipping (default 60 degrees): the 8 support polygons are cut to the 8 faces, so the
# polygon soup covers the octahedron only (37.8% of the image, framed like the points, whose discs
# cover 41.1%); unclipped, each polygon is its domain's footprint (alpha > tau, 40.5%: the basis
# functions reach over the edges; whole rectangles, before the footprint, covered 67.1%)
"$AMGSPLAT" render "$T/o.dps" -o "$T/pc.png" --size 64x64 --method polygons -q
"$AMGSPLAT" render "$T/o.dps" -o "$T/pu.png" --size 64x64 --method polygons --crease-angle off -q
"$AMGSPLAT" render "$T/o.dps" -o "$T/nc.png" --size 64x64 --method normalized --crease-angle 45 -q
check "$T/pc.png" "0.33 < fg < 0.42"
check "$T/pu.png" "0.39 < fg < 0.45"
check "$T/nc.png" "0.33 < fg < 0.42"
expect_fail 2 "--crease-angle expects" "$AMGSPLAT" render "$T/o.dps" -o "$T/x.png" --crease-angle 180
expect_fail 2 "--crease-angle expects" "$AMGSPLAT" render "$T/o.dps" -o "$T/x.png" --crease-angle soft

# --outline draws green edges (journal Fig. 12b); --color-by domain changes the colours
"$AMGSPLAT" render "$T/o.dps" -o "$T/out.png" --size 48x48 --method polygons --outline -q
check "$T/out.png" "sum(px(x, y)[:3] == (0, 255, 0) for x in range(w) for y in range(h)) > 20"
check "$T/normalized.png" "sum(px(x, y)[:3] == (0, 255, 0) for x in range(w) for y in range(h)) == 0"
"$AMGSPLAT" render "$T/o.dps" -o "$T/dom.png" --size 48x48 --view 30,20 --color-by domain -q
cmp -s "$T/dom.png" "$T/normalized.png" && fail "--color-by domain changed nothing"

# --transparency 0.5 over a transparent background: half the opacity
"$AMGSPLAT" render "$T/o.dps" -o "$T/half.png" --size 48x48 --view 0,0 --transparent --transparency 0.5 -q
check "$T/half.png" "126 <= px(24, 24)[3] <= 129"

# a contact sheet, and the same bytes twice
"$AMGSPLAT" render "$T/o.dps" -o "$T/sheet.png" --size 24x24 --views 4 --method prefix -q
check "$T/sheet.png" "w == 48 and h == 48"
"$AMGSPLAT" render "$T/o.dps" -o "$T/sheet2.png" --size 24x24 --views 4 --method prefix -q
cmp -s "$T/sheet.png" "$T/sheet2.png" || fail "two identical renders differ"

# usage errors (exit 2) and input errors (exit 1)
expect_fail 2 "unknown rendering method 'bogus'" "$AMGSPLAT" render "$T/o.dps" -o "$T/x.png" --method bogus
expect_fail 2 "need a .dps input" "$AMGSPLAT" render "$T/o.ply" -o "$T/x.png" --method overlap
expect_fail 2 "--renderer is for point inputs" "$AMGSPLAT" render "$T/o.dps" -o "$T/x.png" --renderer splat
expect_fail 2 "--alpha-ref expects" "$AMGSPLAT" render "$T/o.dps" -o "$T/x.png" --alpha-ref 2
expect_fail 2 "--transparency expects" "$AMGSPLAT" render "$T/o.dps" -o "$T/x.png" --transparency 0
# -1 was the "not given" marker and so accepted silently (issue 13)
expect_fail 2 "--transparency expects" "$AMGSPLAT" render "$T/o.dps" -o "$T/x.png" --transparency -1
expect_fail 2 "--depth-window expects" "$AMGSPLAT" render "$T/o.dps" -o "$T/x.png" --depth-window -1
expect_fail 2 "--alpha-ref expects" "$AMGSPLAT" render "$T/o.dps" -o "$T/x.png" --alpha-ref -1
expect_fail 2 "--color-by on a .dps input expects domain" "$AMGSPLAT" render "$T/o.dps" -o "$T/x.png" --color-by strict
expect_fail 1 "has no level 'L-3'" "$AMGSPLAT" render "$T/o.dps" -o "$T/x.png" --level L-3
head -c 2000 "$T/o.dps" >"$T/cut.dps"
expect_fail 1 "cut.dps" "$AMGSPLAT" render "$T/cut.dps" -o "$T/x.png"
[[ ! -e "$T/x.png" ]] || fail "a failed render left an output file"
echo "render_dps: ok"
