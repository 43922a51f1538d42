# ctest-label: e2e
# The streamed tileset in the browser (issue 32): `export --tiles` of Spot's textured points, opened
# by the page (web/test/tiles.mjs: three.js + 3d-tiles-renderer in headless Chromium).
# The point file's tileset (streamed route, refine ADD, one tile a node, discs):
#  - its GLBs pass gltf-validator (root, an inner tile, a leaf);
#  - the first frame comes after exactly tileset.json and the root tile (coarse first; the 5% of the
#    issue holds from about a million points, bench/bench_tiles.sh measures it on 10M);
#  - once refined (more bytes, more points), the picture matches `amgsplat render` of the same
#    points' streamed hierarchy at the same view (SSIM >= 0.9, unlit: discs without normals), and a
#    view of another azimuth does not pass;
#  - CesiumJS (web/test/cesium.mjs) loads this default tileset without errors.
# An in-memory .hier's tileset (tools/seed_hier; REPLACE, Gaussian splats):
#  - its GLBs pass gltf-validator (root, an inner tile, a leaf);
#  - the first frame comes after <= 5% of the tileset's bytes (the page's count and the server's);
#  - once refined, the picture matches `amgsplat render` of the same points at the same view
#    (SSIM >= 0.9, the issue's line), better than the first frame does, and a view of another
#    azimuth does not pass;
#  - a point budget holds: with point-budget 20000 the settled view shows at most that many splats;
#  - CesiumJS (web/test/cesium.mjs) loads the tileset without errors. Cesium 1.145 cannot draw
#    meshopt-compressed KHR_gaussian_splatting (it names GLSL variables after the attributes,
#    "khr_gaussian_splatting:opacity"), so for an in-memory .hier that check reads the --no-splats
#    tileset; Gaussian splats in Cesium are --splat-codec spz, checked by web_cesium.sh.
#  - a .dps tileset (one tile a level) streams from the coarsest level to the finest, which matches
#    `amgsplat render` of that level (SSIM >= 0.95), and CesiumJS loads it.
# Skips (77) without node, web/node_modules or Chromium.
source "$(dirname "$0")/common.sh"

web="${ASP_TEST_SRC:-$(dirname "$0")/..}/../web"
chromium="${CHROMIUM:-/usr/bin/chromium}"
for m in three puppeteer-core 3d-tiles-renderer cesium gltf-validator; do
  if ! command -v node >/dev/null || [[ ! -d "$web/node_modules/$m" ]]; then
    asp_skipped+=("$web/node_modules/$m (npm ci in web/)")
    exit 0
  fi
done
if [[ ! -x "$chromium" ]]; then
  asp_skipped+=("$chromium")
  exit 0
fi
have_data spot_triangulated.obj spot_texture.png || exit 0

"$AMGSPLAT" sample "$ASP_TEST_DATA/spot_triangulated.obj" --texture "$ASP_TEST_DATA/spot_texture.png" --points 100000 \
  -o "$T/spot.ply" -q

validate_tiles() { # DIR: gltf-validator on the root, an inner tile and a leaf
  local inner leaf
  read -r inner leaf < <(python3 -c "
import json, sys
r = json.load(open(sys.argv[1]))['root']
inner = next(c for c in r['children'] if c.get('children'))
leaf = inner
while leaf.get('children'): leaf = leaf['children'][0]
print(inner['content']['uri'], leaf['content']['uri'])" "$1/tileset.json")
  for f in tiles/0.glb "$inner" "$leaf"; do
    node "$web/test/validate.mjs" "$1/$f" || fail "gltf-validator rejects $1/$f"
  done
}

ssim() { # A.png B.png OP VALUE: SSIM of the two (imgdiff) compared
  "$AMGSPLAT" imgdiff "$1" "$2" --json >"$T/diff.json"
  python3 -c "
import json, sys
d = json.load(open(sys.argv[1]))
print('%s vs %s: SSIM %.4f, PSNR %.2f dB' % (sys.argv[2], sys.argv[3], d['ssim'], d['psnr']))
assert eval('%r %s %s' % (d['ssim'], sys.argv[4], sys.argv[5])), d" "$T/diff.json" "$1" "$2" "$3" "$4" ||
    fail "SSIM of $1 vs $2 not $3 $4: $(cat "$T/diff.json")"
}

# ---- the point file: streamed route, refine ADD ----
"$AMGSPLAT" export "$T/spot.ply" -o "$T/add" --tiles --tile-points 4096 -q
validate_tiles "$T/add"
node "$web/test/tiles.mjs" "$T/add" "$T/addweb" --view 60,15 --size 256x256 --chromium "$chromium" \
  >"$T/add_stream.json" || fail "the page did not stream the ADD tileset"
cat "$T/add_stream.json"
python3 - "$T/add_stream.json" "$T/add" <<'PY' || fail "ADD first frame / refinement figures"
import json, os, sys
s, d = json.load(open(sys.argv[1])), sys.argv[2]
total, f, r = s['tileset_bytes'], s['first_frame'], s['refined']
root = os.path.getsize(os.path.join(d, 'tileset.json')) + os.path.getsize(os.path.join(d, 'tiles/0.glb'))
print(f"ADD: first frame after {f['bytes']} bytes ({100 * f['bytes'] / total:.2f}% of {total}; tileset.json + root "
      f"{root}), {f['requests']} requests; refined: {r['tiles']} tiles, {r['points']} points, {r['bytes']} bytes")
assert f['bytes'] == f['server_bytes'] == root and f['requests'] == 2, 'the first frame waited for more than the root'
assert r['bytes'] > f['bytes'] and r['points'] > f['points'] and r['tiles'] > 1, 'nothing refined'
PY
"$AMGSPLAT" convert "$T/spot.ply" -o "$T/spot_s.hier" --node-points 4096 -q
"$AMGSPLAT" render "$T/spot_s.hier" -o "$T/add_render.png" --unlit --view 60,15 --size 256x256 -q
"$AMGSPLAT" render "$T/spot_s.hier" -o "$T/add_render_other.png" --unlit --view 150,15 --size 256x256 -q
check "$T/addweb_refined.png" "w == 256 and h == 256 and 0.1 < fg < 0.7"
ssim "$T/addweb_refined.png" "$T/add_render.png" ">=" 0.9
ssim "$T/addweb_refined.png" "$T/add_render_other.png" "<" 0.9
node "$web/test/cesium.mjs" "$T/add" --chromium "$chromium" || fail "CesiumJS does not load the ADD tileset"

# a .dps tileset (one tile a level, REPLACE): the page starts from the coarsest level and ends at the
# finest, drawn as `amgsplat render` draws that level (normalized, headlight); Cesium loads it
"$AMGSPLAT" synth torus -o "$T/torus.ply" --points 20000 -q
"$AMGSPLAT" build "$T/torus.ply" -o "$T/torus.dps" --level L-4..L -q || fail "build"
"$AMGSPLAT" export "$T/torus.dps" -o "$T/dps" --tiles -q || fail "export --tiles of a .dps"
node "$web/test/tiles.mjs" "$T/dps" "$T/dps_web" --view 30,40 --size 256x256 --light head --chromium "$chromium" \
  >"$T/dps_stream.json" || fail "the page did not stream the .dps tileset"
finest=$("$AMGSPLAT" info "$T/torus.dps" --json | python3 -c "import json, sys; print(max(json.load(sys.stdin)['levels'], key=lambda l: l['primitives'])['name'])")
"$AMGSPLAT" render "$T/torus.dps" -o "$T/dps_render.png" --level "$finest" --crease-angle off --view 30,40 --size 256x256 -q
python3 - "$T/dps_stream.json" <<'PY' || fail ".dps tileset in the page: $(cat "$T/dps_stream.json")"
import json, sys
s = json.load(open(sys.argv[1]))
f, r = s['first_frame'], s['refined']
print(f".dps tileset: first frame after {f['bytes']} of {s['tileset_bytes']} bytes, {f['points']} primitives; "
      f"refined {r['points']} primitives in {r['tiles']} tile")
assert f['points'] < r['points'] and r['tiles'] == 1 and f['bytes'] < 0.25 * s['tileset_bytes'], s
PY
ssim "$T/dps_web_refined.png" "$T/dps_render.png" ">=" 0.95
node "$web/test/cesium.mjs" "$T/dps" --chromium "$chromium" || fail "CesiumJS does not load the .dps tileset"

# ---- an in-memory .hier: its Gaussian splats, refine REPLACE ----
seed_hier="$(dirname "$AMGSPLAT")/seed_hier"
if [[ ! -x "$seed_hier" ]]; then
  asp_skipped+=("$seed_hier")
  echo "web_tiles: ok"
  exit 0
fi
"$seed_hier" "$T/spot.ply" "$T/spot.hier" || fail "seed_hier"
"$AMGSPLAT" export "$T/spot.hier" -o "$T/tiles" --tiles --tile-points 4096 -q
"$AMGSPLAT" export "$T/spot.hier" -o "$T/plain" --tiles --tile-points 4096 --no-splats -q
validate_tiles "$T/tiles"

node "$web/test/tiles.mjs" "$T/tiles" "$T/web" --view 60,15 --size 256x256 --light head --chromium "$chromium" \
  >"$T/stream.json" || fail "the page did not stream the tileset"
cat "$T/stream.json"
python3 - "$T/stream.json" <<'PY' || fail "first frame / refinement figures"
import json, sys
s = json.load(open(sys.argv[1]))
total, f, r = s['tileset_bytes'], s['first_frame'], s['refined']
print(f"first frame after {f['bytes']} bytes ({100 * f['bytes'] / total:.2f}% of {total}; server {f['server_bytes']}), "
      f"{f['requests']} requests; refined: {r['tiles']} tiles, {r['points']} splats, {r['bytes']} bytes")
assert 0 < f['bytes'] <= 0.05 * total and f['server_bytes'] <= 0.05 * total, 'first frame needs more than 5%'
assert r['bytes'] > f['bytes'] and r['points'] > f['points'], 'nothing refined'
PY
"$AMGSPLAT" render "$T/spot.ply" -o "$T/render.png" --renderer splat --tolerance 0 --lighting flat --samples 1 \
  --crease-angle off --view 60,15 --size 256x256 -q
"$AMGSPLAT" render "$T/spot.ply" -o "$T/render_other.png" --renderer splat --tolerance 0 --lighting flat --samples 1 \
  --crease-angle off --view 150,15 --size 256x256 -q
check "$T/web_refined.png" "w == 256 and h == 256 and 0.1 < fg < 0.7"
ssim "$T/web_refined.png" "$T/render.png" ">=" 0.9
ssim "$T/web_refined.png" "$T/render_other.png" "<" 0.9
# refinement is what matched: the first frame (the root's node splats) is further from the render
"$AMGSPLAT" imgdiff "$T/web_first.png" "$T/render.png" --json >"$T/first.json"
"$AMGSPLAT" imgdiff "$T/web_refined.png" "$T/render.png" --json >"$T/refined.json"
python3 -c "
import json, sys
a, b = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
print('first frame SSIM %.4f, refined %.4f' % (a['ssim'], b['ssim']))
assert a['ssim'] < b['ssim'] - 0.01, (a, b)" "$T/first.json" "$T/refined.json" || fail "refinement changed nothing"

# the point budget
node "$web/test/tiles.mjs" "$T/tiles" "$T/budget" --view 60,15 --size 256x256 --point-budget 20000 \
  --chromium "$chromium" >"$T/budget.json" || fail "the page did not settle under a point budget"
python3 -c "
import json, sys
r = json.load(open(sys.argv[1]))['refined']
print('point budget 20000: %d splats in %d tiles, error target %.2f px' % (r['points'], r['tiles'], r['error_target']))
assert 0 < r['points'] <= 20000 and r['error_target'] > 1.5, r" "$T/budget.json" || fail "point budget exceeded"

# a missing tileset is reported
expect_fail 1 "cannot read" node "$web/test/tiles.mjs" "$T/none" "$T/x" --chromium "$chromium"

# CesiumJS
node "$web/test/cesium.mjs" "$T/plain" --chromium "$chromium" || fail "CesiumJS does not load the tileset"
echo "web_tiles: ok"
