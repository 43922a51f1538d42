# ctest-label: e2e
# amgsplat view: scripted frames in a real window (Xvfb + Mesa llvmpipe through GLX), screenshots
# checked against headless 'amgsplat render' of the same view, keys, .amg colouring, errors.

# The viewer needs a display. xvfb-run is a declared dependency (scripts/bootstrap.sh): the whole
# script runs under one Xvfb server; without xvfb-run it uses $DISPLAY, and without both it fails
# rather than skips, so CI cannot silently lose these checks.
if [[ -z "${ASP_VIEW_UNDER_XVFB:-}" ]] && command -v xvfb-run >/dev/null; then
  ASP_VIEW_UNDER_XVFB=1 exec xvfb-run -a -s "-screen 0 1024x768x24" bash "$0" "$@"
fi
source "$(dirname "$0")/common.sh"
[[ -n "${DISPLAY:-}" ]] || fail "no xvfb-run and no DISPLAY: install xvfb (scripts/bootstrap.sh) to run the viewer tests"
view() { "$AMGSPLAT" view "$@"; }

# metric A B NAME: prints psnr, ssim or iou (of the non-white silhouettes) from imgdiff
metric() { "$AMGSPLAT" imgdiff "$1" "$2" --background 255,255,255 | awk -v m="$3" '$1 == m { print $2 }'; }
# field FILE.json NAME: one value of a --json result
field() { python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])' "$1" "$2"; }
at_least() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a == "inf" || a + 0 >= b) }' || fail "$3: $1 < $2"; }

"$AMGSPLAT" synth sphere -n 3000 -o "$T/sphere.ply" -q

# Scripted mode: 3 frames at a fixed view, screenshot of the last one at the requested size. The
# bounding sphere fills the 120 px height: the unit sphere covers a bit over half the image.
view "$T/sphere.ply" --frames 3 --screenshot "$T/shot.png" --size 160x120 --view 0,0 --json \
  >"$T/shot.json" 2>"$T/shot.err" || fail "view exited $?: $(cat "$T/shot.err")"
[[ -s "$T/shot.png" ]] || fail "no screenshot"
check "$T/shot.png" "w == 160 and h == 120 and 0.40 < fg < 0.62"
check "$T/shot.png" "px(0, 0) == (255, 255, 255, 255) and px(80, 60)[:3] != (255, 255, 255)"
grep -qF "wrote '$T/shot.png' (160x120)" "$T/shot.err" || fail "screenshot name not printed: $(cat "$T/shot.err")"
python3 - "$T/shot.json" <<'PY' || fail "bad --json: $(cat "$T/shot.json")"
import json, sys
j = json.load(open(sys.argv[1]))
assert j['frames'] == 3 and j['width'] == 160 and j['height'] == 120, j
assert j['renderer'] == 'disc' and j['count'] == 3000 and j['screenshots'] == 1, j
assert j['mean_frame_ms'] > 0 and j['gl_renderer'], j
# the window title: file, renderer, count, frame time and frame rate, lighting
import re
assert re.fullmatch(r'amgsplat view: sphere\.ply \| disc \| 3000 points \| [0-9.]+ ms \([0-9]+ fps\) \| lit', j['title']), j['title']
PY

# The window's back buffer matches the headless renderer of the same view: the camera conventions
# agree (identical without multisampling, SSIM >= 0.9 against the default 4x multisampled render).
"$AMGSPLAT" render "$T/sphere.ply" -o "$T/ref0.png" --size 160x120 --view 0,0 --samples 0 -q
"$AMGSPLAT" render "$T/sphere.ply" -o "$T/ref4.png" --size 160x120 --view 0,0 -q
at_least "$(metric "$T/shot.png" "$T/ref0.png" ssim)" 0.99 "viewer vs render --samples 0"
at_least "$(metric "$T/shot.png" "$T/ref4.png" ssim)" 0.9 "viewer vs render"
at_least "$(metric "$T/shot.png" "$T/ref0.png" psnr)" 40 "viewer vs render --samples 0 (PSNR)"

# Keys move the camera as documented: d orbits right by 10 degrees (azimuth -10), z comes 0.85 times
# closer (the fitted distance is 1 / sin(20 deg) radii), r resets to the first view.
view "$T/sphere.ply" --frames 2 --keys d --screenshot "$T/orbit.png" --size 160x120 --view 0,0 -q
"$AMGSPLAT" render "$T/sphere.ply" -o "$T/orbit_ref.png" --size 160x120 --view -10,0 --samples 0 -q
at_least "$(metric "$T/orbit.png" "$T/orbit_ref.png" ssim)" 0.99 "d key vs render --view -10,0"
view "$T/sphere.ply" --frames 1 --keys z --screenshot "$T/zoom.png" --size 160x120 --view 0,0 -q
"$AMGSPLAT" render "$T/sphere.ply" -o "$T/zoom_ref.png" --size 160x120 --view 0,0,2.485234 --samples 0 -q
at_least "$(metric "$T/zoom.png" "$T/zoom_ref.png" ssim)" 0.99 "z key vs render --view 0,0,2.485234"
check "$T/zoom.png" "fg > 0.62"
view "$T/sphere.ply" --frames 4 --keys dzwr --screenshot "$T/reset.png" --size 160x120 --view 0,0 -q
at_least "$(metric "$T/reset.png" "$T/ref0.png" psnr)" 40 "r key resets the view"

# Renderers: 2 = splat, 3 = square (the hierarchy renderers), 8 = compute, n cycles back to disc. The splats cover
# the same silhouette as the discs; tau = 0 draws every point, a larger tau fewer splats, and the
# +/- keys reach the same cut as --tau.
view "$T/sphere.ply" --frames 3 --keys 2 --screenshot "$T/splat.png" --size 160x120 --view 0,0 --json -q >"$T/splat.json"
[[ "$(field "$T/splat.json" renderer)" == splat && "$(field "$T/splat.json" count)" == 3000 ]] || fail "2 key: $(cat "$T/splat.json")"
at_least "$(metric "$T/splat.png" "$T/ref0.png" iou)" 0.98 "splat vs disc silhouette"
at_least "$(metric "$T/splat.png" "$T/ref0.png" ssim)" 0.9 "splat vs disc"
view "$T/sphere.ply" --frames 2 --renderer splat --tau 16 --size 160x120 --view 0,0 --json -q >"$T/t16.json"
c16=$(field "$T/t16.json" count)
[[ "$(field "$T/t16.json" title)" == *"| splat | $c16 splats | "*" | tau 16 px | lit" ]] || fail "title: $(field "$T/t16.json" title)"
(( c16 > 0 && c16 < 3000 )) || fail "tau 16 draws $c16 splats of 3000"
view "$T/sphere.ply" --frames 11 --renderer splat --keys +++++++++++ --size 160x120 --view 0,0 --json -q >"$T/tk.json"
[[ "$(field "$T/tk.json" count)" == "$c16" ]] || fail "11 x + (tau 16) draws $(field "$T/tk.json" count), --tau 16 $c16"
view "$T/sphere.ply" --frames 11 --renderer splat --tau 16 --keys ----------- --size 160x120 --view 0,0 --json -q >"$T/tk0.json"
[[ "$(field "$T/tk0.json" count)" == 3000 ]] || fail "11 x - from tau 16 draws $(field "$T/tk0.json" count)"
view "$T/sphere.ply" --frames 2 --keys 3 --screenshot "$T/square.png" --size 160x120 --view 0,0 --json -q >"$T/sq.json"
[[ "$(field "$T/sq.json" renderer)" == square && "$(field "$T/sq.json" count)" == 3000 ]] || fail "3 key: $(cat "$T/sq.json")"
at_least "$(metric "$T/square.png" "$T/ref0.png" iou)" 0.85 "square vs disc silhouette"
# the point renderers of the table: disc, splat, square, compute (issue 28), then disc again
view "$T/sphere.ply" --frames 5 --keys nnnn --screenshot "$T/cycle.png" --size 160x120 --view 0,0 --json -q >"$T/cycle.json"
[[ "$(field "$T/cycle.json" renderer)" == disc ]] || fail "n x 4 ends at $(field "$T/cycle.json" renderer)"
[[ "$(metric "$T/cycle.png" "$T/ref0.png" psnr)" == inf ]] || fail "disc after a cycle differs from render"
view "$T/sphere.ply" --frames 2 --keys 4+ --size 64x48 2>"$T/r4.err"
grep -qF "renderer 'prim' unavailable: renderer 'prim' cannot draw points input" "$T/r4.err" &&
  grep -qF "applies to the hierarchy renderers" "$T/r4.err" || fail "4, + on disc: $(cat "$T/r4.err")"

# l turns lighting off: same silhouette, flat colours (the rim is no darker than the centre's colour)
view "$T/sphere.ply" --frames 1 --keys l --screenshot "$T/unlit.png" --size 160x120 --view 0,0 -q
[[ "$(metric "$T/unlit.png" "$T/shot.png" iou)" == "1.000000" ]] || fail "unlit changes the silhouette"
ssim=$(metric "$T/unlit.png" "$T/shot.png" ssim)
awk -v s="$ssim" 'BEGIN { exit !(s < 0.99) }' || fail "l key changed nothing (SSIM $ssim)"
view "$T/sphere.ply" --frames 1 --unlit --screenshot "$T/unlit2.png" --size 160x120 --view 0,0 -q
[[ "$(metric "$T/unlit.png" "$T/unlit2.png" psnr)" == "inf" ]] || fail "--unlit differs from the l key"

# s writes <input>-NNN.png into the current directory, numbering past existing files
mkdir -p "$T/shots" && touch "$T/shots/sphere-001.png"
(cd "$T/shots" && view ../sphere.ply --frames 2 --keys ss --size 64x48 2>"$T/s.err") || fail "s key: $(cat "$T/s.err")"
grep -qF "wrote 'sphere-002.png' (64x48)" "$T/s.err" || fail "s key: $(cat "$T/s.err")"
grep -qF "wrote 'sphere-003.png' (64x48)" "$T/s.err" || fail "s key: $(cat "$T/s.err")"
check "$T/shots/sphere-003.png" "w == 64 and h == 48 and 0.3 < fg < 0.7"

# Interactive mode (no --frames) runs until q: keys are pressed one per loop turn, s saves the frame
(cd "$T/shots" && timeout 60 "$AMGSPLAT" view ../sphere.ply --keys dsq --size 64x48 --json \
  >"$T/i.json" 2>"$T/i.err") || fail "interactive q: exit $?: $(cat "$T/i.err")"
[[ "$(field "$T/i.json" frames)" == 2 && "$(field "$T/i.json" screenshots)" == 1 ]] || fail "interactive: $(cat "$T/i.json")"
grep -qF "wrote 'sphere-004.png' (64x48)" "$T/i.err" || fail "interactive s: $(cat "$T/i.err")"

# h prints every key; v prints the view in the form --view takes
view "$T/sphere.ply" --frames 2 --keys hv --size 64x48 --view 12,-34,5 2>"$T/h.err" >/dev/null
for k in q r l n + - c '[' ']' s v h a d w x z Z 1 4 m , . o p; do
  grep -q "^  [$k]  " "$T/h.err" || fail "help lacks key $k: $(cat "$T/h.err")"
done
grep -qF "view: --view 12.0,-34.0,5.000" "$T/h.err" || fail "v key: $(cat "$T/h.err")"

# .amg input: classifier colours, then the domains of the coarsest level; ] at the coarsest level says so
"$AMGSPLAT" synth octahedron -n 2000 -o "$T/oct.ply" -q
# decompose starts MPI, whose by-design leaks LSan matches only with full stacks (CMakeLists.txt)
ASAN_OPTIONS="${ASAN_OPTIONS:-}:fast_unwind_on_malloc=0" "$AMGSPLAT" decompose "$T/oct.ply" -o "$T/oct.amg" -q
view "$T/oct.amg" --frames 1 --screenshot "$T/classifier.png" --size 96x96 -q
view "$T/oct.amg" --frames 2 --keys ']' --screenshot "$T/domains.png" --size 96x96 2>"$T/amg.err"
grep -qE "^domains, level [0-9]+ \(L-0\), [0-9]+ domains" "$T/amg.err" || fail "] key: $(cat "$T/amg.err")"
[[ "$(metric "$T/classifier.png" "$T/domains.png" iou)" == "1.000000" ]] || fail "colour modes change the shape"
ssim=$(metric "$T/classifier.png" "$T/domains.png" ssim)
awk -v s="$ssim" 'BEGIN { exit !(s < 0.98) }' || fail "] did not recolour (SSIM $ssim)"
view "$T/oct.amg" --frames 3 --color domains --keys ']c' --size 64x64 2>"$T/amg2.err"
grep -qF "already at the coarsest level" "$T/amg2.err" || fail "] at L: $(cat "$T/amg2.err")"
grep -qE "^strict domains, level" "$T/amg2.err" || fail "c key: $(cat "$T/amg2.err")"
# the same colours as the option says: --color domains --level L-1 equals [ from L
view "$T/oct.amg" --frames 1 --color domains --level L-1 --screenshot "$T/lm1.png" --size 96x96 -q
view "$T/oct.amg" --frames 2 --color domains --keys '[' --screenshot "$T/lm1k.png" --size 96x96 -q
[[ "$(metric "$T/lm1.png" "$T/lm1k.png" psnr)" == "inf" ]] || fail "[ differs from --level L-1"
# colour keys on a plain point file are explained, not fatal
view "$T/sphere.ply" --frames 1 --keys c --size 64x48 2>"$T/c.err"
grep -qF ".amg and .dps input only" "$T/c.err" || fail "c on points: $(cat "$T/c.err")"
view "$T/sphere.ply" --frames 2 --keys mp --size 64x48 2>"$T/mp.err"
grep -qF "apply to .dps input only" "$T/mp.err" && grep -qF "p applies to .dps input only" "$T/mp.err" ||
  fail "m, p on points: $(cat "$T/mp.err")"

# .dps input: the octahedron's coarsest level L has its 8 faces as domains (decompose --stats), L-1 9.
"$AMGSPLAT" synth octahedron -o "$T/o.ply" -q
mpi_asan="${ASAN_OPTIONS:-}:fast_unwind_on_malloc=0"
ASAN_OPTIONS="$mpi_asan" "$AMGSPLAT" decompose "$T/o.ply" -o "$T/o.amg" -q
ASAN_OPTIONS="$mpi_asan" "$AMGSPLAT" build "$T/o.amg" -o "$T/o.dps" --level 'L-1..L' -q >/dev/null
# the scripted view of level L equals the headless render of the same method and view
view "$T/o.dps" --frames 3 --screenshot "$T/dps.png" --method prefix --level L --size 160x120 --view 30,20 --json \
  -q >"$T/dps.json"
"$AMGSPLAT" render "$T/o.dps" -o "$T/dps_ref.png" --method prefix --level L --samples 0 --size 160x120 --view 30,20 -q
at_least "$(metric "$T/dps.png" "$T/dps_ref.png" ssim)" 0.9 "view .dps vs render .dps"
check "$T/dps.png" "0.1 < fg < 0.7"
python3 - "$T/dps.json" <<'PY' || fail "bad .dps --json: $(cat "$T/dps.json")"
import json, re, sys
j = json.load(open(sys.argv[1]))
assert j['renderer'] == 'prim' and j['count'] == 8, j
assert re.fullmatch(r'amgsplat view: o\.dps \| prim \| 8 primitives \| [0-9.]+ ms \([0-9]+ fps\) \| prefix, alpha-ref 0\.10 \| lit \| level 10 \(L\)', j['title']), j['title']
PY
# default: the finest level in the file (L-1, one primitive per domain: 10 since the Morton numbering
# of src/amg/morton.c, 9 before), method normalized; --alpha-ref shows in the title
"$AMGSPLAT" decompose "$T/o.amg" --json -q >"$T/o_levels.json"
lm1=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['level_sizes'][-2])" "$T/o_levels.json")
view "$T/o.dps" --frames 1 --alpha-ref 0.3 --size 64x48 --json -q >"$T/dps0.json"
[[ "$(field "$T/dps0.json" count)" == "$lm1" && "$(field "$T/dps0.json" title)" == *"| normalized, alpha-ref 0.30 | lit | level 9 (L-1)" ]] ||
  fail "default .dps view: $(cat "$T/dps0.json")"
# m cycles to the next method: the picture and the title change; ] steps to level L (8 primitives);
# o draws the outlines (green edges); c colours by domain; , and . step the alpha reference by 0.05
view "$T/o.dps" --frames 2 --keys m --method prefix --level L --screenshot "$T/dps_m.png" --size 160x120 --view 30,20 \
  --json 2>"$T/dps_m.err" >"$T/dps_m.json"
grep -qx "method overlap" "$T/dps_m.err" || fail "m key: $(cat "$T/dps_m.err")"
[[ "$(field "$T/dps_m.json" title)" == *"| overlap, alpha-ref 0.10 |"* ]] || fail "m title: $(cat "$T/dps_m.json")"
"$AMGSPLAT" render "$T/o.dps" -o "$T/dps_ov.png" --method overlap --level L --samples 0 --size 160x120 --view 30,20 -q
at_least "$(metric "$T/dps_m.png" "$T/dps_ov.png" ssim)" 0.9 "m key vs render --method overlap"
view "$T/o.dps" --frames 2 --keys ']' --method prefix --screenshot "$T/dps_l.png" --size 160x120 --view 30,20 \
  --json 2>"$T/dps_l.err" >"$T/dps_l.json"
grep -qF "level 10 (L), 8 primitives" "$T/dps_l.err" && [[ "$(field "$T/dps_l.json" count)" == 8 ]] ||
  fail "] key: $(cat "$T/dps_l.err" "$T/dps_l.json")"
# (framed on L-1's bounding sphere, so close to, not equal to the --level L view)
at_least "$(metric "$T/dps_l.png" "$T/dps.png" ssim)" 0.9 "] vs --level L"
view "$T/o.dps" --frames 3 --keys '[]' --method prefix --level L --screenshot "$T/dps_l3.png" --size 160x120 \
  --view 30,20 2>"$T/dps_l3.err"
grep -qF "level 9 (L-1), $lm1 primitives" "$T/dps_l3.err" || fail "[ key: $(cat "$T/dps_l3.err")"
[[ "$(metric "$T/dps_l3.png" "$T/dps.png" psnr)" == inf ]] || fail "[ then ] differs from --level L"
view "$T/o.dps" --frames 3 --keys ']]' --size 64x48 2>"$T/dps_l2.err"
grep -qF "already at the coarsest level in the file (10)" "$T/dps_l2.err" || fail "] at L: $(cat "$T/dps_l2.err")"
view "$T/o.dps" --frames 2 --keys o --method prefix --level L --screenshot "$T/dps_o.png" --size 160x120 --view 30,20 \
  --json -q >"$T/dps_o.json"
[[ "$(field "$T/dps_o.json" title)" == *"prefix, alpha-ref 0.10, outline |"* ]] || fail "o title: $(cat "$T/dps_o.json")"
check "$T/dps_o.png" "sum(1 for x in range(w) for y in range(h) if px(x, y)[1] > 200 and px(x, y)[0] < 80 and px(x, y)[2] < 80) > 50"
check "$T/dps.png" "sum(1 for x in range(w) for y in range(h) if px(x, y)[1] > 200 and px(x, y)[0] < 80 and px(x, y)[2] < 80) == 0"
"$AMGSPLAT" render "$T/o.dps" -o "$T/dps_oref.png" --method prefix --level L --outline --samples 0 --size 160x120 --view 30,20 -q
at_least "$(metric "$T/dps_o.png" "$T/dps_oref.png" ssim)" 0.9 "o key vs render --outline"
view "$T/o.dps" --frames 2 --keys c --method prefix --level L --screenshot "$T/dps_c.png" --size 160x120 --view 30,20 \
  --json -q >"$T/dps_c.json"
[[ "$(field "$T/dps_c.json" title)" == *", domain colours |"* ]] || fail "c title: $(cat "$T/dps_c.json")"
ssim=$(metric "$T/dps_c.png" "$T/dps.png" ssim)
awk -v s="$ssim" 'BEGIN { exit !(s < 0.98) }' || fail "c on .dps changed nothing (SSIM $ssim)"
view "$T/o.dps" --frames 6 --keys ',,,..' --size 64x48 --json 2>"$T/dps_a.err" >"$T/dps_a.json"
[[ "$(grep -c '^alpha reference' "$T/dps_a.err")" == 5 ]] && grep -qx "alpha reference 0.00" "$T/dps_a.err" ||
  fail "alpha keys: $(cat "$T/dps_a.err")"
[[ "$(field "$T/dps_a.json" title)" == *"alpha-ref 0.10 |"* ]] || fail "alpha keys title: $(cat "$T/dps_a.json")"
# p shows the source points (the .amg the .dps names) with the disc renderer, then the primitives again
view "$T/o.dps" --frames 2 --keys p --level L --screenshot "$T/dps_p.png" --size 160x120 --view 30,20 \
  --json 2>"$T/dps_p.err" >"$T/dps_p.json"
[[ "$(field "$T/dps_p.json" renderer)" == disc && "$(field "$T/dps_p.json" count)" == 16000 ]] ||
  fail "p key: $(cat "$T/dps_p.json")"
grep -qx "showing the source points" "$T/dps_p.err" || fail "p key: $(cat "$T/dps_p.err")"
at_least "$(metric "$T/dps_p.png" "$T/dps.png" iou)" 0.9 "source points vs primitives silhouette"
view "$T/o.dps" --frames 3 --keys pp --level L --screenshot "$T/dps_pp.png" --method prefix --size 160x120 --view 30,20 \
  --json -q >"$T/dps_pp.json"
[[ "$(field "$T/dps_pp.json" renderer)" == prim && "$(metric "$T/dps_pp.png" "$T/dps.png" psnr)" == inf ]] ||
  fail "pp does not return to the primitives: $(cat "$T/dps_pp.json")"
# a .dps whose source is gone: p explains and the primitives stay
mkdir -p "$T/lone" && cp "$T/o.dps" "$T/lone/moved.dps"
mv "$T/o.amg" "$T/o.amg.away"
view "$T/lone/moved.dps" --frames 3 --keys pp --size 64x48 --json 2>"$T/lone.err" >"$T/lone.json"
mv "$T/o.amg.away" "$T/o.amg"
[[ "$(grep -cF "cannot show the source points: cannot open" "$T/lone.err")" == 2 ]] &&
  [[ "$(field "$T/lone.json" renderer)" == prim ]] || fail "p without a source: $(cat "$T/lone.err" "$T/lone.json")"
# .dps errors: unknown level or method, .dps options on other input, the prim renderer on points
expect_fail 1 "has no level 'L-5'" view "$T/o.dps" --frames 1 --level L-5
expect_fail 2 "--method:" "$AMGSPLAT" view "$T/o.dps" --method blob
expect_fail 2 "--alpha-ref expects" "$AMGSPLAT" view "$T/o.dps" --alpha-ref 1.5
expect_fail 2 "--alpha-ref expects" "$AMGSPLAT" view "$T/o.dps" --alpha-ref -1
expect_fail 2 "need a .dps input" "$AMGSPLAT" view "$T/sphere.ply" --method prefix
expect_fail 1 "renderer 'prim' cannot draw points input" view "$T/sphere.ply" --frames 1 --renderer prim
expect_fail 1 "renderer 'disc' cannot draw dps input" view "$T/o.dps" --frames 1 --renderer disc

# A scan without normals (issue 29): ground (ASPRS class 2) and a box-shaped building (class 6) on it,
# z up, with an intensity; no normals, no colours, as a LAS export gives them.
python3 - "$T/scan.ply" <<'PY'
import random, sys
random.seed(7)
pts = []
for i in range(6000):
    x, y = random.uniform(-10, 10), random.uniform(-10, 10)
    if abs(x) < 3 and abs(y) < 3:
        continue
    pts.append((x, y, random.gauss(0, 0.02), 2, 200))
for i in range(4000):
    f = random.random()
    if f < 0.5:
        p = (random.uniform(-3, 3), random.uniform(-3, 3), 4.0)
    elif f < 0.75:
        p = (random.choice((-3, 3)), random.uniform(-3, 3), random.uniform(0, 4))
    else:
        p = (random.uniform(-3, 3), random.choice((-3, 3)), random.uniform(0, 4))
    pts.append(p + (6, 800))
with open(sys.argv[1], 'w') as f:
    f.write('ply\nformat ascii 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\n'
            'property uchar classification\nproperty ushort intensity\nend_header\n' % len(pts))
    f.writelines('%.4f %.4f %.4f %d %d\n' % p for p in pts)
PY
# --color-by classification: the ASPRS palette of render --color-by (ground 150,100,50, building
# 230,80,40; src/geom/scalar_colors.c), pixel for pixel the same as render's with shading off
view "$T/scan.ply" --frames 2 --up z --color-by classification --unlit --size 160x120 --view 30,35 \
  --screenshot "$T/cls.png" --json -q >"$T/cls.json"
"$AMGSPLAT" render "$T/scan.ply" --up z --color-by classification --unlit --samples 0 --size 160x120 --view 30,35 \
  -o "$T/cls_ref.png" -q
[[ "$(metric "$T/cls.png" "$T/cls_ref.png" psnr)" == inf ]] || fail "view --color-by classification differs from render"
check "$T/cls.png" "sum(1 for x in range(w) for y in range(h) if px(x, y)[:3] == (150, 100, 50)) > 1500"
check "$T/cls.png" "sum(1 for x in range(w) for y in range(h) if px(x, y)[:3] == (230, 80, 40)) > 400"
check "$T/cls.png" "all(px(x, y)[:3] in ((255, 255, 255), (150, 100, 50), (230, 80, 40)) for x in range(w) for y in range(h))"
[[ "$(field "$T/cls.json" edl)" == False ]] || fail "--unlit left eye-dome lighting on: $(cat "$T/cls.json")"
view "$T/scan.ply" --frames 1 --up z --color-by elevation --size 64x48 -q || fail "view --color-by elevation"
expect_fail 2 "no such property 'colour' (elevation or the file's: classification, intensity)" view "$T/scan.ply" --frames 1 --color-by colour
expect_fail 2 "--color-by expects classifier" "$AMGSPLAT" view "$T/oct.amg" --color-by elevation

# Eye-dome lighting: on by default for points without normals; it shades the flat grey discs (the
# building's edges and the ground behind it go dark; SSIM 0.78 on llvmpipe) without moving the
# silhouette; E turns it off.
view "$T/scan.ply" --frames 2 --up z --size 160x120 --view 30,35 --screenshot "$T/edl.png" --json \
  >"$T/edl.json" 2>"$T/edl.err"
view "$T/scan.ply" --frames 2 --up z --size 160x120 --view 30,35 --no-edl --screenshot "$T/noedl.png" -q
view "$T/scan.ply" --frames 2 --up z --size 160x120 --view 30,35 --keys E --screenshot "$T/edl_e.png" \
  --json -q >"$T/edl_e.json"
[[ "$(field "$T/edl.json" edl)" == True && "$(field "$T/edl_e.json" edl)" == False ]] ||
  fail "edl flags: $(cat "$T/edl.json" "$T/edl_e.json")"
[[ "$(metric "$T/edl.png" "$T/noedl.png" iou)" == "1.000000" ]] || fail "eye-dome lighting moved the silhouette"
ssim=$(metric "$T/edl.png" "$T/noedl.png" ssim)
awk -v s="$ssim" 'BEGIN { exit !(s < 0.9) }' || fail "eye-dome lighting changed too little (SSIM $ssim)"
[[ "$(metric "$T/edl_e.png" "$T/noedl.png" psnr)" == inf ]] || fail "E differs from --no-edl"
# without it the discs face the eye and are all one grey; with it a quarter of the model is darker
check "$T/noedl.png" "sum(1 for x in range(w) for y in range(h) if px(x, y)[0] < 150) == 0"
check "$T/edl.png" "sum(1 for x in range(w) for y in range(h) if px(x, y)[0] < 150) > 0.25 * fg * w * h"
# the hint that estimate gives normals: once per run, and not with --quiet or on points with normals
[[ "$(grep -c "has no normals: drawn with eye-dome lighting (E toggles it); 'amgsplat estimate" "$T/edl.err")" == 1 ]] ||
  fail "hint: $(cat "$T/edl.err")"
view "$T/scan.ply" --frames 3 --up z --size 64x48 --keys 21 -q 2>"$T/edl_q.err"
[[ ! -s "$T/edl_q.err" ]] || fail "--quiet printed: $(cat "$T/edl_q.err")"
view "$T/sphere.ply" --frames 1 --size 64x48 2>"$T/sph.err"
! grep -q "hint:" "$T/sph.err" || fail "hint on a cloud with normals: $(cat "$T/sph.err")"
expect_fail 2 "--no-edl excludes" "$AMGSPLAT" view "$T/scan.ply" --edl --no-edl
# render draws the same shading (default on without normals) and says the same hint once
"$AMGSPLAT" render "$T/scan.ply" --up z --size 160x120 --view 30,35 -o "$T/r_edl.png" 2>"$T/r_edl.err"
"$AMGSPLAT" render "$T/scan.ply" --up z --size 160x120 --view 30,35 -o "$T/r_noedl.png" --no-edl -q 2>"$T/r_q.err"
[[ "$(grep -c "hint: '$T/scan.ply' has no normals: drawn with eye-dome lighting; 'amgsplat estimate" "$T/r_edl.err")" == 1 &&
   ! -s "$T/r_q.err" ]] || fail "render hint: $(cat "$T/r_edl.err" "$T/r_q.err")"
ssim=$(metric "$T/r_edl.png" "$T/r_noedl.png" ssim)
awk -v s="$ssim" 'BEGIN { exit !(s < 0.9) }' || fail "render: eye-dome lighting changed too little (SSIM $ssim)"
at_least "$(metric "$T/r_edl.png" "$T/edl.png" ssim)" 0.9 "render vs view with eye-dome lighting"
"$AMGSPLAT" render "$T/sphere.ply" --size 160x120 --view 0,0 -o "$T/r_sph.png" --samples 0 2>"$T/r_sph.err"
! grep -q "hint:" "$T/r_sph.err" && [[ "$(metric "$T/r_sph.png" "$T/ref0.png" psnr)" == inf ]] ||
  fail "points with normals: a hint or eye-dome lighting: $(cat "$T/r_sph.err")"
"$AMGSPLAT" render "$T/sphere.ply" --size 160x120 --view 0,0 -o "$T/r_sph_edl.png" --samples 0 --edl -q
ssim=$(metric "$T/r_sph_edl.png" "$T/ref0.png" ssim)
awk -v s="$ssim" 'BEGIN { exit !(s < 0.99) }' || fail "render --edl on points with normals changed nothing (SSIM $ssim)"
expect_fail 2 "--edl and --edl-strength need --renderer disc or square" "$AMGSPLAT" render "$T/scan.ply" -o "$T/x.png" --edl --renderer splat
expect_fail 2 "--edl-strength expects a number in (0, 100]" "$AMGSPLAT" render "$T/scan.ply" -o "$T/x.png" --edl-strength 0

# The figures (i) name the file, renderer, level or method; the first frame has no frame time yet.
view "$T/sphere.ply" --frames 1 --overlay --size 320x240 --screenshot "$T/ov1.png" --json -q >"$T/ov1.json"
python3 - "$T/ov1.json" <<'PY' || fail "first frame figures: $(cat "$T/ov1.json")"
import json, re, sys
t = json.load(open(sys.argv[1]))['overlay'].split('\n')
assert t[0] == 'sphere.ply' and t[1] == 'renderer disc', t
assert re.fullmatch(r'frame -- ms  first draw [0-9.]+ ms \(with GL warm-up\)', t[2]), t
PY
check "$T/ov1.png" "px(10, 10)[0] < 200 and px(300, 230)[:3] == (255, 255, 255)"
view "$T/o.dps" --frames 3 --keys i --method prefix --level L --size 320x240 --screenshot "$T/ov_dps.png" --json -q \
  >"$T/ov_dps.json"
python3 - "$T/ov_dps.json" <<'PY' || fail "figures of a .dps: $(cat "$T/ov_dps.json")"
import json, re, sys
t = json.load(open(sys.argv[1]))['overlay'].split('\n')
assert t[:3] == ['o.dps', 'renderer prim: prefix, alpha-ref 0.10', 'level 10 (L)'], t
assert re.fullmatch(r'frame [0-9.]+ ms  draw [0-9.]+ ms', t[3]) and t[4] == '8 / 8 primitives', t
PY
view "$T/scan.ply" --frames 2 --keys i --up z --color-by intensity --size 320x240 --json -q >"$T/ov_scan.json"
[[ "$(field "$T/ov_scan.json" overlay)" == "scan.ply"$'\n'"renderer disc, eye-dome lighting"$'\n'"colour by intensity"$'\n'* ]] ||
  fail "figures of a scan: $(field "$T/ov_scan.json" overlay)"
# h shows the keys over the frame as well as printing them; h again hides them
view "$T/sphere.ply" --frames 2 --keys h --size 480x400 --view 0,0 --screenshot "$T/help.png" 2>"$T/help.err"
grep -q "^  E  toggle eye-dome lighting" "$T/help.err" || fail "h did not print: $(cat "$T/help.err")"
# a window too narrow for two columns gets the lines that fit, nothing cut at the right edge; a wide
# one gets both columns side by side, above the bottom
check "$T/help.png" "px(10, 10)[0] < 200 and px(10, 380)[0] < 200 and px(470, 20)[:3] == (255, 255, 255)"
view "$T/sphere.ply" --frames 2 --keys h --size 1024x400 --view 0,0 --screenshot "$T/help_wide.png" -q
check "$T/help_wide.png" "px(10, 10)[0] < 200 and px(700, 20)[0] < 200 and px(10, 380)[:3] == (255, 255, 255)"
check "$T/shot.png" "px(10, 10)[:3] == (255, 255, 255)"
view "$T/sphere.ply" --frames 3 --keys hh --size 160x120 --view 0,0 --screenshot "$T/help2.png" -q
[[ "$(metric "$T/help2.png" "$T/ref0.png" psnr)" == inf ]] || fail "h h leaves text on the frame"
# --frame-ms without --renderer draws with a renderer it steers (splat), and says so
view "$T/sphere.ply" --frames 3 --frame-ms 50 --size 128x96 --json >"$T/fb.json" 2>"$T/fb.err"
[[ "$(field "$T/fb.json" renderer)" == splat && "$(field "$T/fb.json" budget_applied)" == True ]] ||
  fail "--frame-ms default renderer: $(cat "$T/fb.json")"
grep -qF "drawing with the splat renderer, whose tau it steers" "$T/fb.err" || fail "--frame-ms: $(cat "$T/fb.err")"

# Errors: a missing or bad file exits 1 naming it (before any window opens); bad options exit 2.
expect_fail 1 "cannot open '$T/missing.ply'" view "$T/missing.ply" --frames 1
printf 'ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nend_header\n' >"$T/empty.ply"
expect_fail 1 "empty.ply" view "$T/empty.ply" --frames 1
expect_fail 1 "L-99" view "$T/oct.amg" --frames 1 --level L-99
expect_fail 2 "unknown option '--bogus'" "$AMGSPLAT" view "$T/sphere.ply" --bogus
expect_fail 2 "unknown renderer 'blob'" "$AMGSPLAT" view "$T/sphere.ply" --renderer blob
expect_fail 2 "key 'Q'" "$AMGSPLAT" view "$T/sphere.ply" --frames 2 --keys lQ
expect_fail 2 "needs a number of frames" "$AMGSPLAT" view "$T/sphere.ply" --screenshot "$T/x.png"
expect_fail 2 "must end in .png" "$AMGSPLAT" view "$T/sphere.ply" --frames 1 --screenshot "$T/x.jpg"
expect_fail 2 "--size expects WxH" "$AMGSPLAT" view "$T/sphere.ply" --size 0x10
expect_fail 2 "--view expects" "$AMGSPLAT" view "$T/sphere.ply" --view 0,95
expect_fail 2 "--color expects" "$AMGSPLAT" view "$T/oct.amg" --color rainbow
expect_fail 2 "--tau expects" "$AMGSPLAT" view "$T/sphere.ply" --tau -1
expect_fail 2 "expected one input file" "$AMGSPLAT" view
# no display at all: a clear GL error, exit 1
expect_fail 1 "no OpenGL 4.5 window" env -u DISPLAY -u WAYLAND_DISPLAY "$AMGSPLAT" view "$T/sphere.ply" --frames 1
[[ ! -e "$T/x.png" && ! -e "$T/x.jpg" ]] || fail "a failed run left a file"
"$AMGSPLAT" view -h | grep "usage: amgsplat view" >/dev/null || fail "-h"
echo "view: ok"
