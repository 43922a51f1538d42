# amgsplat render --hybrid (issue 18 item 3, docs/hybrid.md): a cube's primitives where they hold,
# its points where a primitive straddles an edge, blended in one normalised sum. The split is
# reported and consistent, the source is found beside the .dps or given, the picture is closer to
# the points than either pure-primitive method, and misuse fails cleanly.
source "$(dirname "$0")/common.sh"

"$AMGSPLAT" synth cube -o "$T/c.ply" --points 6000 -q
mpi_asan="${ASAN_OPTIONS:-}:fast_unwind_on_malloc=0"
ASAN_OPTIONS="$mpi_asan" "$AMGSPLAT" decompose "$T/c.ply" -o "$T/c.amg" -q
ASAN_OPTIONS="$mpi_asan" "$AMGSPLAT" build "$T/c.amg" -o "$T/c.dps" --level L-4 -q >/dev/null

"$AMGSPLAT" render "$T/c.dps" -o "$T/h.png" --size 96x96 --hybrid --transparent --json >"$T/json"
python3 -c "
import json, sys
d = json.load(open(sys.argv[1]))
h = d['hybrid']
assert d['renderer'] == 'hybrid' and d['method'] == 'hybrid', d
# every primitive is kept or replaced; some of each on a cube (faces hold, edges do not)
assert h['primitives_kept'] + h['primitives_replaced'] == d['points'], d
assert h['primitives_kept'] > 0 and h['primitives_replaced'] > 0, h
assert h['points_total'] == 6000 and 0 < h['points_drawn'] < h['points_total'], h
# what was drawn: the kept primitives and at least some splats of the drawn points' hierarchy
assert d['primitives'] > h['primitives_kept'], d
" "$T/json" || fail "json: $(cat "$T/json")"
check "$T/h.png" "px(48, 48)[3] == 255 and px(0, 0)[3] == 0"

# the source named in the .dps (c.amg) and the points given directly draw the same picture
"$AMGSPLAT" render "$T/c.dps" -o "$T/h2.png" --size 96x96 --hybrid-points "$T/c.ply" --transparent -q
cmp -s "$T/h.png" "$T/h2.png" || fail "--hybrid-points c.ply differs from the .dps's own source"

# closer to the points (opaque discs) than the best pure-primitive method, in three views
for v in 30,20 120,-20 200,40; do
  "$AMGSPLAT" render "$T/c.ply" -o "$T/ref.png" --size 96x96 --view "$v" --transparent -q
  "$AMGSPLAT" render "$T/c.dps" -o "$T/hv.png" --size 96x96 --view "$v" --transparent --hybrid -q
  best=0
  for m in normalized prefix; do
    "$AMGSPLAT" render "$T/c.dps" -o "$T/$m.png" --size 96x96 --view "$v" --transparent --method "$m" -q
    s=$("$AMGSPLAT" imgdiff --json "$T/$m.png" "$T/ref.png" | python3 -c "import json,sys; print(json.load(sys.stdin)['ssim'])")
    best=$(python3 -c "print(max($best, $s))")
  done
  sh=$("$AMGSPLAT" imgdiff --json "$T/hv.png" "$T/ref.png" | python3 -c "import json,sys; print(json.load(sys.stdin)['ssim'])")
  python3 -c "import sys; sys.exit(0 if $sh > $best else 1)" || fail "view $v: hybrid SSIM $sh <= best primitives $best"
done

# misuse
expect_fail 2 "--hybrid needs a .dps input" "$AMGSPLAT" render "$T/c.ply" -o "$T/x.png" --hybrid
expect_fail 1 "missing.ply" "$AMGSPLAT" render "$T/c.dps" -o "$T/x.png" --hybrid-points "$T/missing.ply"
cp "$T/c.dps" "$T/alone.dps" && mv "$T/c.amg" "$T/c.amg.away"
# c.amg is named by relative or absolute path: make sure neither resolves
(cd "$T" && expect_fail 1 "c.amg" "$AMGSPLAT" render alone.dps -o x.png --hybrid)
mv "$T/c.amg.away" "$T/c.amg"
echo ok
