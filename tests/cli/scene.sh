# amgsplat scene field and scene files of instances (docs/scene-format.md): the generator is
# deterministic for a seed and writes what it says; render draws a 50-instance field; a near
# instance of domain primitives hides a far point instance and vice versa whatever the file order
# (the primitives' resolve paints without a depth test: the scene renderer draws far to near); info
# and view take scene files; bad scenes and options fail cleanly, naming what is wrong.
if [[ -z "${ASP_VIEW_UNDER_XVFB:-}" ]] && command -v xvfb-run >/dev/null; then
  ASP_VIEW_UNDER_XVFB=1 exec xvfb-run -a -s "-screen 0 1024x768x24" bash "$0" "$@"
fi
source "$(dirname "$0")/common.sh"
A=$AMGSPLAT
field() { python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])' "$1" "$2"; }

"$A" synth cube -n 6000 -o "$T/cube.ply" -q
"$A" synth sphere -n 6000 -o "$T/sphere.ply" -q
mpi_asan="${ASAN_OPTIONS:-}:fast_unwind_on_malloc=0"
ASAN_OPTIONS="$mpi_asan" "$A" decompose "$T/cube.ply" -o "$T/cube.amg" -q
ASAN_OPTIONS="$mpi_asan" "$A" build "$T/cube.amg" -o "$T/cube.dps" --primitives 30 -q >/dev/null

# help and usage errors
"$A" scene -h | grep -F "scene field MODEL" >/dev/null || fail "scene -h"
"$A" scene field -h | grep -F -- "--instances" >/dev/null || fail "scene field -h"
expect_fail 2 "missing -o" "$A" scene field "$T/sphere.ply" --instances 5
expect_fail 2 "writes .json" "$A" scene field "$T/sphere.ply" --instances 5 -o "$T/f.png"
expect_fail 2 "--instances expects 1..1000000" "$A" scene field "$T/sphere.ply" --instances 0 -o "$T/f.json"
expect_fail 2 "--jitter" "$A" scene field "$T/sphere.ply" --instances 5 --jitter 2 -o "$T/f.json"
expect_fail 2 "unknown subcommand 'meadow'" "$A" scene meadow
expect_fail 1 "cannot open" "$A" scene field "$T/none.ply" --instances 5 -o "$T/f.json"

# deterministic for a seed, different for another; the model is named relative to the scene file
"$A" scene field "$T/sphere.ply" --instances 50 --seed 3 -o "$T/f1.json" -q
"$A" scene field "$T/sphere.ply" --instances 50 --seed 3 -o "$T/f2.json" --json >"$T/f2.out"
"$A" scene field "$T/sphere.ply" --instances 50 --seed 4 -o "$T/f3.json" -q
cmp -s "$T/f1.json" "$T/f2.json" || fail "the same seed gave two different files"
cmp -s "$T/f1.json" "$T/f3.json" && fail "seeds 3 and 4 gave the same file"
[[ $(field "$T/f2.out" instances) == 50 ]] || fail "scene field --json: $(cat "$T/f2.out")"
python3 - "$T/f1.json" <<'PY' || fail "field file: $(head -c 400 "$T/f1.json")"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["version"] == 1 and len(s["instances"]) == 50
assert all(i["source"] == "sphere.ply" and len(i["matrix"]) == 16 for i in s["instances"])
# the unit sphere stands on y = 0: every model lifts it by its radius
assert all(0.99 < i["matrix"][13] < 1.01 for i in s["instances"])
zs = [i["matrix"][14] for i in s["instances"]]
assert s["camera"]["eye"][2] > max(zs) and s["camera"]["target"][2] < min(zs) + 5
PY
"$A" info "$T/f1.json" | grep -F "scene of 50 instances of 1 source" >/dev/null || fail "info on a scene"

# a 50-instance field renders: near instances large, far ones small, all in one frame
"$A" render "$T/f1.json" -o "$T/f1.png" --size 160x120 --json >"$T/r.json" || fail "render of a field"
python3 - "$T/r.json" <<'PY' || fail "render --json: $(cat "$T/r.json")"
import json, sys
r = json.load(open(sys.argv[1]))
assert r["instances"] == 50 and r["renderer"] == "scene" and 10 <= r["instances_drawn"] <= 50, r
assert r["primitives"] == 6000 * r["instances_drawn"], r
PY
check "$T/f1.png" "w == 160 and h == 120 and 0.05 < fg < 0.8"
"$A" render "$T/f1.json" -o "$T/f1s.png" --size 160x120 --renderer splat --tolerance 2 -q
check "$T/f1s.png" "0.05 < fg < 0.8"

# eval of a scene: the reference against itself is exact; coarser cuts draw fewer splats
"$A" scene field "$T/sphere.ply" --instances 6 -o "$T/f6.json" -q
"$A" eval "$T/f6.json" -o "$T/ev" --sizes 64 --frames 1 --tolerances 2,8 --json >"$T/ev.out" || fail "eval of a scene"
python3 - "$T/ev.out" "$T/ev/eval.json" <<'PY' || fail "eval --json: $(cat "$T/ev.out")"
import json, sys
out, saved = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
rows = out["rows"]
assert [r["renderer"] for r in rows] == ["splat", "disc", "splat", "splat", "square"], rows
assert rows[0]["psnr"] is None and rows[0]["ssim"] == 1 and rows[0]["iou"] == 1, rows[0]
assert rows[3]["primitives"] < rows[2]["primitives"] < rows[0]["primitives"], rows
assert all(0.3 < r["ssim"] <= 1 and r["frame_ms"] > 0 for r in rows), rows
assert len(saved["rows"]) == 5 and saved["rows"][0]["reference"] is True
PY
# one row of the 5 tiles under a title and each tile's label (renderer, tau, SSIM, count)
check "$T/ev/sheet.png" "fg > 0.05 and h > 64 + 30 and w >= 5 * 64"
expect_fail 2 "--tolerances is for scene files" "$A" eval "$T/sphere.ply" --tolerances 1

# occlusion with domain primitives: the near instance covers the centre whichever comes first
cam='"camera": {"eye": [0, 0, 9], "target": [0, 0, 0], "fov": 40}'
echo "{\"version\": 1, \"instances\": [{\"source\": \"cube.dps\"}], $cam}" >"$T/near_only.json"
echo "{\"version\": 1, \"instances\": [{\"source\": \"sphere.ply\", \"translate\": [0, 0, -6], \"scale\": 3}], $cam}" >"$T/far_only.json"
echo "{\"version\": 1, \"instances\": [{\"source\": \"cube.dps\"}, {\"source\": \"sphere.ply\", \"translate\": [0, 0, -6], \"scale\": 3}], $cam}" >"$T/a.json"
echo "{\"version\": 1, \"instances\": [{\"source\": \"sphere.ply\", \"translate\": [0, 0, -6], \"scale\": 3}, {\"source\": \"cube.dps\"}], $cam}" >"$T/b.json"
echo "{\"version\": 1, \"instances\": [{\"source\": \"cube.ply\", \"translate\": [0, 0, -6], \"scale\": 2}, {\"source\": \"sphere.ply\"}], $cam}" >"$T/c.json"
echo "{\"version\": 1, \"instances\": [{\"source\": \"sphere.ply\"}], $cam}" >"$T/c_near.json"
for f in near_only far_only a b c c_near; do
  "$A" render "$T/$f.json" -o "$T/$f.png" --size 96x96 --samples 1 -q || fail "render $f"
done
centre() { python3 "$(dirname "$0")/png_check.py" "$1" "print(px(48, 48)) or True"; }
near=$(centre "$T/near_only.png"); far=$(centre "$T/far_only.png")
[[ $near != "$far" ]] || fail "near and far instances look alike at the centre: $near"
for f in a b; do
  [[ $(centre "$T/$f.png") == "$near" ]] || fail "$f.json: centre $(centre "$T/$f.png"), expected the near primitives' $near (far: $far)"
done
[[ $(centre "$T/c.png") == "$(centre "$T/c_near.png")" ]] || fail "c.json: the near sphere is hidden"
# the seeds' methods paint without a depth test: the scene renderer's far-to-near order decides
for f in near_only a b; do
  "$A" render "$T/$f.json" -o "$T/$f-2p.png" --size 96x96 --samples 1 --method two-pass -q || fail "render $f two-pass"
done
# alike A B: two "(r, g, b, a)" tuples within 8 per channel (a resolve's rounding differs by one)
alike() { python3 -c 'import sys; a, b = eval(sys.argv[1]), eval(sys.argv[2]); sys.exit(max(abs(x - y) for x, y in zip(a, b)) > 8)' "$1" "$2"; }
for f in a b; do
  alike "$(centre "$T/$f-2p.png")" "$(centre "$T/near_only-2p.png")" ||
    fail "$f.json two-pass: centre $(centre "$T/$f-2p.png"), expected the near primitives' $(centre "$T/near_only-2p.png")"
done

# the viewer draws a scene too (its own camera, scripted frames)
if [[ -n "${DISPLAY:-}" ]]; then
  "$A" view "$T/a.json" --frames 2 --size 96x96 --screenshot "$T/view.png" -q || fail "view of a scene"
  check "$T/view.png" "0.2 < fg"
  [[ $(centre "$T/view.png") == "$near" ]] || echo "note: the viewer's centre $(centre "$T/view.png") differs from render's $near (multisampling)" >&2
fi

# bad scene files: the message names the file, the instance and the field or source
echo '{"version": 1, "instances": [{"source": "sphere.ply"}, {"source": "sphere.ply", "scale": -2}]}' >"$T/bad1.json"
expect_fail 1 "bad1.json' instance 1: 'scale' must be a number > 0" "$A" render "$T/bad1.json" -o "$T/x.png"
echo '{"version": 1, "instances": [{"source": "sphere.ply"}, {"source": "gone.ply"}]}' >"$T/bad2.json"
expect_fail 1 "bad2.json' instance 1 source 'gone.ply': cannot open" "$A" render "$T/bad2.json" -o "$T/x.png"
echo '{"version": 1, "instances": [{"source": "bad1.json"}]}' >"$T/bad3.json"
expect_fail 1 "scene inside a scene" "$A" render "$T/bad3.json" -o "$T/x.png"
expect_fail 2 "--budget is per model" "$A" render "$T/f1.json" -o "$T/x.png" --budget 100
expect_fail 2 "--renderer is the scene's point sources' renderer" "$A" render "$T/f1.json" -o "$T/x.png" --renderer prim
[[ ! -e "$T/x.png" ]] || fail "a failed render left an image"
exit 0
