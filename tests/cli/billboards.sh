# amgsplat simplify --billboards (issue 30; Decoret et al. 2003): a box plus a field of crossed quads
# made here (a triangle soup: disconnected, intersecting) becomes a billboard cloud .dps that info,
# render and export read; the render is not empty and its silhouette matches the mesh's render; the
# bound is kept; bad options are refused with messages.
source "$(dirname "$0")/common.sh"
python3 - "$T" <<'PY'
import math, random, sys
random.seed(3)
v, f = [], []
def quad(p):
    b = len(v) + 1; v.extend(p); f.extend([(b, b + 1, b + 2), (b, b + 2, b + 3)])
for c in range(30):   # crossed quads on the ground, like foliage cards
    cx, cz, a = random.uniform(-4, 4), random.uniform(-4, 4), random.uniform(0, math.pi)
    h, w = 1 + random.random(), 0.5 + 0.5 * random.random()
    for q in range(2):
        ang = a + q * math.pi / 2; dx, dz = math.cos(ang) * w, math.sin(ang) * w
        quad([(cx - dx, 0, cz - dz), (cx + dx, 0, cz + dz), (cx + dx, h, cz + dz), (cx - dx, h, cz - dz)])
s = 1.5           # a box standing in the middle, 12 triangles
P = [(x, y, z) for x in (-s, s) for y in (0, 2 * s) for z in (-s, s)]
for q in ((0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)):
    quad([P[i] for i in q])
with open(sys.argv[1] + '/soup.obj', 'w') as o:
    for p in v: o.write('v %g %g %g\n' % p)
    for t in f: o.write('f %d %d %d\n' % t)
PY
A=$AMGSPLAT
"$A" simplify "$T/soup.obj" --billboards --error 0.02 --texels 300000 -o "$T/bb.dps" --json >"$T/j" || fail "simplify"
python3 - "$T/j" <<'PY' || fail "json: $(cat "$T/j")"
import json, sys
d = json.load(open(sys.argv[1]))
assert d['elements'] == 132 and d['uncovered'] == 0, d
# 66 planar quads: never more planes than quads, and the box needs its 6 sides
assert 6 <= d['planes'] <= 66, d
assert d['max_distance'] <= d['error_world'] * 1.0001, d
assert abs(d['texels'] - 300000) < 0.05 * 300000, d
PY
"$A" info "$T/bb.dps" >"$T/info" || fail "info"
# info marks the level as billboards (atlas flags bit 2), in text and JSON
grep -Eq "^ +0  .* billboards$" "$T/info" || fail "info does not mark the billboard level: $(cat "$T/info")"
"$A" info "$T/bb.dps" --json >"$T/info.json" || fail "info --json"
python3 -c 'import json,sys; l=json.load(open(sys.argv[1]))["levels"]; assert len(l) == 1 and l[0]["kind"] == "billboards", l' \
  "$T/info.json" || fail "info --json: level kind is not billboards: $(cat "$T/info.json")"
# the mesh and its billboards from the same cameras (a .dps is framed by the mesh's frame)
"$A" render "$T/soup.obj" -o "$T/mesh.png" --size 192x192 --view 30,25 -q || fail "render mesh"
"$A" render "$T/bb.dps" -o "$T/bb.png" --size 192x192 --view 30,25 -q || fail "render billboards"
"$A" imgdiff "$T/mesh.png" "$T/bb.png" --json >"$T/d" || fail "imgdiff"
python3 - "$T/d" <<'PY' || fail "billboards against the mesh: $(cat "$T/d")"
import json, sys
d = json.load(open(sys.argv[1]))
# not empty: about as many silhouette pixels as the mesh; and the same silhouette (0.91 when written)
assert d['silhouette'][1]['pixels'] > 0.8 * d['silhouette'][0]['pixels'], d
assert d['iou'] > 0.85 and d['ssim'] > 0.6, d
PY
# export: a glTF whose material masks
"$A" export "$T/bb.dps" -o "$T/bb.gltf" -q || fail "export"
python3 -c 'import json,sys; g=json.load(open(sys.argv[1])); m=g["materials"]; assert m and all(x["alphaMode"] == "MASK" for x in m), m; assert all(n["extras"]["amgsplat"]["billboards"] for n in g["nodes"] if "mesh" in n), g["nodes"]' \
  "$T/bb.gltf" || fail "export: not every material masks"
# bad options
expect_fail 2 "--billboards needs --error" "$A" simplify "$T/soup.obj" --billboards -o "$T/x.dps"
expect_fail 2 "give -o OUT.dps" "$A" simplify "$T/soup.obj" --billboards --error 0.05 -o "$T/x.obj"
expect_fail 2 "not both" "$A" simplify "$T/soup.obj" --billboards --error 0.05 --texels 10 --texel-size 0.1 -o "$T/x.dps"
expect_fail 2 "need --billboards" "$A" simplify "$T/soup.obj" --triangles 10 --planes 3 -o "$T/x.obj"
# a plane budget leaves faces out and says so
"$A" simplify "$T/soup.obj" --billboards --error 0.01 --planes 2 -o "$T/p.dps" 2>"$T/err" >/dev/null || fail "--planes"
grep "left" "$T/err" >/dev/null || fail "--planes: no note of uncovered faces: $(cat "$T/err")"
echo ok
