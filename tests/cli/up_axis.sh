#!/bin/bash
# A z-up scan stands upright everywhere (issue 29): a LAS site with a 16 m tower (2 x 2 m, red) on 60 x 40 m
# of ground (green), taken through decompose and build, renders with the tower upright from the .las,
# the .amg and the .dps with no --up (the files record the axis, `info` shows it), in `view` too,
# and lying down with --up y; the framing of this flat, wide site fills more of a 16:9 image than the sphere did;
# export turns the scan to glTF's y-up: three.js's GLTFLoader (web/test/up_axis.mjs) and the web
# page (web/test/screenshot.mjs) show it upright, and the LAS's CRS is kept in asset.extras.
source "$(dirname "$0")/common.sh"
A=$AMGSPLAT
python3 - "$T/site.ply" <<'PY'
import math, sys
pts = []
for i in range(61):
    for j in range(41):
        x, y = i * 1.0, j * 1.0
        pts.append((500000 + x, 4100000 + y, 100 + 0.8 * math.sin(x / 9) + 0.5 * math.cos(y / 7), 90, 160, 90))
for k in range(41):  # the tower: 2 x 2 m, 16 m tall along z, its four walls every 0.4 m
    for a in range(20):
        s, e = (a % 5) * 0.4 - 1, 1 - 2 * (a // 5 % 2)  # along the wall, which side
        x, y = (s, e) if a < 10 else (e, s)
        pts.append((500040 + x, 4100020 + y, 100 + k * 0.4, 230, 20, 20))
with open(sys.argv[1], 'w') as f:
    f.write('ply\nformat ascii 1.0\nelement vertex %d\nproperty double x\nproperty double y\nproperty double z\n'
            'property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n' % len(pts))
    for p in pts:
        f.write('%.3f %.3f %.3f %d %d %d\n' % p)
PY
"$A" convert -q "$T/site.ply" -o "$T/site.las"
"$A" decompose -q "$T/site.las" -o "$T/site.amg"
"$A" build -q "$T/site.amg" -o "$T/site.dps" --primitives 1500 >/dev/null
for f in site.amg site.dps; do
  "$A" info "$T/$f" --json | python3 -c 'import json, sys; f = json.load(sys.stdin)["frame"]; assert f["up"] == "z" and f["box"][0] > 50, f' ||
    fail "$f: info does not show the recorded up axis z and the box"
done

# the tower's pixels (red) span 2.5 times more rows than columns: it stands upright; lying, fewer
TALL='(lambda p: len(p) > 20 and max(y for x, y in p) - min(y for x, y in p) > 2.5 * (max(x for x, y in p) - min(x for x, y in p) + 1))([(x, y) for x in range(w) for y in range(h) if px(x, y)[0] > 150 and px(x, y)[1] < 100])'
LYING='(lambda p: len(p) > 20 and max(y for x, y in p) - min(y for x, y in p) < max(x for x, y in p) - min(x for x, y in p) + 1)([(x, y) for x in range(w) for y in range(h) if px(x, y)[0] > 150 and px(x, y)[1] < 100])'
for f in site.las site.amg site.dps; do
  "$A" render -q "$T/$f" -o "$T/${f/./_}.png" --size 200x200 --unlit
  check "$T/${f/./_}.png" "$TALL"
  "$A" render -q "$T/$f" -o "$T/${f/./_}_y.png" --size 200x200 --unlit --up y
  check "$T/${f/./_}_y.png" "$LYING"
done

# the viewer takes the recorded axis too (scripted frames, screenshot of the last)
if command -v xvfb-run >/dev/null || [[ -n "${DISPLAY:-}" ]]; then
  view() { if [[ -n "${DISPLAY:-}" ]]; then "$A" view "$@"; else xvfb-run -a -s "-screen 0 1024x768x24" "$A" view "$@"; fi; }
  for f in site.las site.dps; do
    view "$T/$f" --frames 2 --screenshot "$T/view_${f/./_}.png" --size 200x200 --unlit -q
    check "$T/view_${f/./_}.png" "$TALL"
  done
  view "$T/site.dps" --frames 2 --screenshot "$T/view_dps_y.png" --size 200x200 --unlit --up y -q
  check "$T/view_dps_y.png" "$LYING"
else
  asp_skipped+=("xvfb-run or a DISPLAY (the viewer's up axis)")
fi

# framing: at 16:9 the site's box fills more of the image than its bounding sphere did (the sphere's
# distance is r / sin(20 deg) = 2.924 radii at fov 40)
"$A" render -q "$T/site.las" -o "$T/wide.png" --size 320x180 --unlit
"$A" render -q "$T/site.las" -o "$T/wide_sphere.png" --size 320x180 --unlit --view 30,20,2.9238
FILL='sum(px(x, y)[:3] != (255, 255, 255) for x in range(w) for y in range(h)) / (w * h)'
box=$(python3 "$(dirname "$0")/png_check.py" "$T/wide.png" "print(round($FILL, 4)) or True")
sphere=$(python3 "$(dirname "$0")/png_check.py" "$T/wide_sphere.png" "print(round($FILL, 4)) or True")
echo "16:9 image filled: box framing $box, sphere framing $sphere"
awk -v a="$box" -v b="$sphere" 'BEGIN { exit !(a >= 1.5 * b) }' || fail "box framing fills $box, sphere $sphere: expected 1.5x"

# export keeps the CRS a LAS names (WKT and GeoTIFF keys, las_handmade.py --crs) in asset.extras
python3 "$(dirname "$0")/las_handmade.py" "$T/crs.las" 4 6 200 --crs >/dev/null
"$A" export -q "$T/crs.las" -o "$T/crs.glb"
python3 - "$T/crs.glb" <<'PY' || fail "crs.glb: the LAS's CRS is not in asset.extras.amgsplat.crs"
import json, struct, sys
d = open(sys.argv[1], 'rb').read()
j = json.loads(d[20:20 + struct.unpack('<I', d[12:16])[0]])
crs = j['asset']['extras']['amgsplat']['crs']
assert crs['wkt'].startswith('PROJCS["WGS 84 / UTM zone 33N"') and crs['epsg'] == 32633 and crs['epsgVertical'] == 5703, crs
assert crs['geoKeys'][:4] == [1, 1, 0, 3], crs
ex = j['scenes'][0]['extras']['amgsplat']
assert ex['sourceUp'] == 'z' and ex['toSource'] == [1, 0, 0, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1], ex
print('crs: EPSG', crs['epsg'], 'vertical', crs['epsgVertical'])
PY

# export: y-up glTF; the three.js check runs where node and web/node_modules are
"$A" export -q "$T/site.las" -o "$T/site.glb"
"$A" export -q "$T/site.dps" -o "$T/site_dps.glb"
WEB="$(cd "$(dirname "$0")/../../web" && pwd)"
if command -v node >/dev/null && [[ -d "$WEB/node_modules/three" ]]; then
  node "$WEB/test/up_axis.mjs" "$T/site.glb" "$T/site_dps.glb" || fail "exported scan is not y-up in three.js"
  # and the project's web page shows it upright (headless Chromium)
  if [[ -x "${CHROMIUM:-/usr/bin/chromium}" ]]; then
    for f in site site_dps; do
      node "$WEB/test/screenshot.mjs" "$T/$f.glb" "$T/web_$f.png" --size 200x200 >/dev/null
      check "$T/web_$f.png" "$TALL"
    done
  else
    asp_skipped+=("${CHROMIUM:-/usr/bin/chromium} (the web page's picture of the export)")
  fi
else
  asp_skipped+=("node with web/node_modules/three (the three.js check of the exported scan)")
fi
echo "PASS up_axis"
