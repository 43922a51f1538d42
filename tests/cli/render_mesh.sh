# amgsplat render MESH (issue 14): material, vertex and texture colours on decoded pixels, a missing
# texture drawn in its material colour with a warning, OBJ without UVs, PLY with faces, OFF, flat
# normals, and the textured spot mesh against discs sampled from it (SSIM, same framing).
source "$(dirname "$0")/common.sh"

# A unit quad in the xy plane facing +z (the camera at --view 0,0): under the headlight its lit colour
# is exactly its colour. OBJ with a material whose texture file is missing (Kd = red), OBJ without
# UVs or materials, PLY with faces and one vertex colour per corner, OFF, glTF, and an octahedron.
python3 - "$T" <<'PY'
import sys
d = sys.argv[1]
open(d + '/red.mtl', 'w').write('newmtl redmat\nKd 1 0 0\nmap_Kd no_such_texture.png\n')
open(d + '/missing.obj', 'w').write('mtllib red.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n'
    'vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl redmat\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n')
open(d + '/nouv.obj', 'w').write('v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3\nf 1 3 4\n')
with open(d + '/quad.ply', 'w') as f:
    f.write('ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n'
            'property uchar red\nproperty uchar green\nproperty uchar blue\nelement face 2\n'
            'property list uchar int vertex_indices\nend_header\n')
    # all four corners one colour: interpolation cannot blur it, so the centre must show it exactly
    for x, y in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
        f.write('%d %d 0 40 160 90\n' % (x, y))
    f.write('3 0 1 2\n3 0 2 3\n')
open(d + '/quad.off', 'w').write('OFF\n4 2 0\n-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n3 0 1 2\n3 0 2 3\n')
import base64, json, struct
b = struct.pack('<12f', -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0) + struct.pack('<6H', 0, 1, 2, 0, 2, 3) + b'\0\0'
json.dump({'asset': {'version': '2.0'}, 'scenes': [{'nodes': [0]}], 'scene': 0, 'nodes': [{'mesh': 0}],
           'meshes': [{'primitives': [{'attributes': {'POSITION': 0}, 'indices': 1, 'material': 0}]}],
           'materials': [{'pbrMetallicRoughness': {'baseColorFactor': [0, 0, 1, 1]}}],
           'buffers': [{'byteLength': len(b), 'uri': 'data:application/octet-stream;base64,' + base64.b64encode(b).decode()}],
           'bufferViews': [{'buffer': 0, 'byteOffset': 0, 'byteLength': 48}, {'buffer': 0, 'byteOffset': 48, 'byteLength': 12}],
           'accessors': [{'bufferView': 0, 'componentType': 5126, 'count': 4, 'type': 'VEC3', 'min': [-1, -1, 0], 'max': [1, 1, 0]},
                         {'bufferView': 1, 'componentType': 5123, 'count': 6, 'type': 'SCALAR'}]},
          open(d + '/quad.gltf', 'w'))
v = ['1 0 0', '-1 0 0', '0 1 0', '0 -1 0', '0 0 1', '0 0 -1']
faces = [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)]
open(d + '/octa.off', 'w').write('OFF\n6 8 0\n' + '\n'.join(v) + '\n' +
                                 ''.join('3 %d %d %d\n' % f for f in faces))
PY

near() { echo "all(abs(a - b) <= $2 for a, b in zip(px(w // 2, h // 2)[:3], $1))"; }

# A missing texture: rendered (exit 0) in the material colour, with a warning naming the file.
expect_exit 0 "$AMGSPLAT" render "$T/missing.obj" -o "$T/missing.png" --size 64x64 --view 0,0 -q
grep -F "no_such_texture.png" "$T/err" >/dev/null || fail "no warning naming the missing texture: $(cat "$T/err")"
grep -F "warning" "$T/err" >/dev/null || fail "the missing texture is not a warning: $(cat "$T/err")"
check "$T/missing.png" "$(near '(255, 0, 0)' 1)"
# the quad fills the middle of the view, the corners stay background
check "$T/missing.png" "px(0, 0)[:3] == (255, 255, 255) and 0.2 < fg < 0.8"

# view MESH: the mesh renderer by default, the same warning (through the viewer's log) and colour.
# The viewer needs a display: Xvfb as in view.sh.
viewer() {
  if command -v xvfb-run >/dev/null; then xvfb-run -a -s "-screen 0 1024x768x24" "$AMGSPLAT" view "$@"
  elif [[ -n "${DISPLAY:-}" ]]; then "$AMGSPLAT" view "$@"
  else fail "no xvfb-run and no DISPLAY: install xvfb (scripts/bootstrap.sh) to run the viewer"; fi
}
viewer "$T/missing.obj" --frames 2 --screenshot "$T/view.png" --size 96x96 --view 0,0 --json >"$T/view.json" \
  2>"$T/view.err" || fail "view of a mesh failed: $(cat "$T/view.err")"
grep -F '"renderer": "mesh"' "$T/view.json" >/dev/null || fail "view does not draw the mesh: $(cat "$T/view.json")"
grep -F "no_such_texture.png" "$T/view.err" >/dev/null || fail "view does not warn: $(cat "$T/view.err")"
check "$T/view.png" "$(near '(255, 0, 0)' 1)"

# OBJ without UVs or materials: the point renderers' light grey 200
"$AMGSPLAT" render "$T/nouv.obj" -o "$T/nouv.png" --size 64x64 --view 0,0 -q
check "$T/nouv.png" "$(near '(200, 200, 200)' 1)"
# ... lit from 60 degrees aside: 200 in linear light times 0.25 + 0.75 cos 60 = 0.625 -> sRGB 161
"$AMGSPLAT" render "$T/nouv.obj" -o "$T/side.png" --size 64x64 --view 0,0 --light 60,0 -q
check "$T/side.png" "$(near '(161, 161, 161)' 2)"

# PLY with faces and vertex colours; its vertices are points too (--renderer disc)
"$AMGSPLAT" render "$T/quad.ply" -o "$T/ply.png" --size 64x64 --view 0,0 -q --json >"$T/ply.json"
check "$T/ply.png" "$(near '(40, 160, 90)' 1)"
grep -F '"renderer": "mesh"' "$T/ply.json" >/dev/null || fail "a PLY with faces is not drawn as a mesh: $(cat "$T/ply.json")"
grep -F '"points": 2,' "$T/ply.json" >/dev/null || fail "the PLY mesh does not count 2 triangles: $(cat "$T/ply.json")"
"$AMGSPLAT" render "$T/quad.ply" -o "$T/ply_disc.png" --size 64x64 --view 0,0 --renderer disc -q
check "$T/ply_disc.png" "fg > 0.01"

# OFF: assimp's OFF importer gives an unnamed material of grey 0.6, which the sampler draws as 153
# (255 Kd); should the loader come to treat it as no colour, the light grey 200 of colourless points
"$AMGSPLAT" render "$T/quad.off" -o "$T/off.png" --size 64x64 --view 0,0 -q
check "$T/off.png" "$(near '(153, 153, 153)' 1) or $(near '(200, 200, 200)' 1)"

# glTF: the base colour factor (blue)
"$AMGSPLAT" render "$T/quad.gltf" -o "$T/gltf.png" --size 64x64 --view 0,0 -q
check "$T/gltf.png" "$(near '(0, 0, 255)' 1)"

# Flat normals: seen along (1, 1, 1), the octahedron's face (+x, +y, +z) faces the eye. With --flat
# it shows one shade, its full colour (153 or 200, as the OFF above); without, the vertex normals
# point along the axes and the shade falls off from its middle (measured 153 -> 143 at these two pixels).
"$AMGSPLAT" render "$T/octa.off" -o "$T/flat.png" --size 96x96 --view 45,35.26 --flat -q
"$AMGSPLAT" render "$T/octa.off" -o "$T/smooth.png" --size 96x96 --view 45,35.26 -q
check "$T/flat.png" "abs(px(48, 46)[0] - px(48, 70)[0]) <= 1 and px(48, 46)[0] in (152, 153, 154, 199, 200, 201)"
check "$T/smooth.png" "px(48, 46)[0] - px(48, 70)[0] >= 6"

# point renderers on a mesh that is not a PLY: told to sample it
expect_fail 2 "sample the mesh to points first" "$AMGSPLAT" render "$T/quad.off" -o "$T/x.png" --renderer splat

# mesh-only options on points are refused
python3 -c "print('ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n1 0 0\n0 1 0')" >"$T/pts.ply"
expect_fail 2 "need a mesh input" "$AMGSPLAT" render "$T/pts.ply" -o "$T/x.png" --flat
expect_fail 2 "unknown renderer 'mesh'" "$AMGSPLAT" render "$T/pts.ply" -o "$T/x.png" --renderer mesh

# The textured spot mesh against discs from 200k area samples of it, 4 views of 128x128 (the issue's
# done-when is 1M samples, 16 views of 256x256: mean SSIM 0.982, docs/cli/render.md). Measured here:
# mean SSIM 0.961 (views 0.963, 0.958, 0.963, 0.959; seeds 1-3 give 0.960-0.964), so >= 0.95. Both
# inputs must frame alike: the samples' frame adds their largest disc radius (measured: +1.1% of the
# radius at 200k samples, +0.5% at 1M) and its centre moves by < 0.05%; checked within 2%.
if have_data spot_triangulated.obj spot_texture.png; then
  D="$ASP_TEST_DATA"
  "$AMGSPLAT" sample "$D/spot_triangulated.obj" --texture "$D/spot_texture.png" --method area \
    --points 200000 -o "$T/spot.ply" -q
  total=0
  for i in 0 1 2 3; do
    az=$((30 + 90 * i)); el=$((i % 2 ? -20 : 20))
    "$AMGSPLAT" render "$D/spot_triangulated.obj" --texture "$D/spot_texture.png" -o "$T/m$i.png" \
      --size 128x128 --view $az,$el -q --json >"$T/m$i.json"
    "$AMGSPLAT" render "$T/spot.ply" -o "$T/p$i.png" --size 128x128 --view $az,$el -q --json >"$T/p$i.json"
    "$AMGSPLAT" imgdiff "$T/m$i.png" "$T/p$i.png" --json >"$T/d$i.json"
  done
  python3 - "$T" <<'PY' || fail "spot mesh and its samples differ"
import json, sys
d = sys.argv[1]
ssim = [json.load(open('%s/d%d.json' % (d, i)))['ssim'] for i in range(4)]
iou = [json.load(open('%s/d%d.json' % (d, i)))['iou'] for i in range(4)]
print('spot mesh vs 200k discs: SSIM', ssim, 'IoU', iou)
assert sum(ssim) / 4 >= 0.95, 'mean SSIM %.4f < 0.95' % (sum(ssim) / 4)
assert min(iou) >= 0.95, 'silhouette IoU %s' % iou
fm = json.load(open(d + '/m0.json'))['frame']
fp = json.load(open(d + '/p0.json'))['frame']
r = fm[3]
assert all(abs(a - b) < 0.02 * r for a, b in zip(fm, fp)), 'frames differ: %s %s' % (fm, fp)
PY
  # view: p shows 200,000 area samples of the mesh as discs in the mesh's frame, p again the mesh
  viewer "$D/spot_triangulated.obj" --texture "$D/spot_texture.png" --frames 3 --keys p --size 128x128 \
    --view 30,20 --screenshot "$T/vp.png" --json -q >"$T/vp.json" || fail "view p on a mesh failed"
  grep -F '"renderer": "disc"' "$T/vp.json" >/dev/null && grep -F '"count": 200000,' "$T/vp.json" >/dev/null ||
    fail "p on a mesh does not show its 200000 points: $(cat "$T/vp.json")"
  "$AMGSPLAT" imgdiff "$T/vp.png" "$T/m0.png" --json >"$T/vpd.json"
  python3 -c "import json,sys; d=json.load(open(sys.argv[1])); assert d['ssim'] >= 0.93 and d['iou'] >= 0.95, d" \
    "$T/vpd.json" || fail "the viewer's points are not the mesh's picture: $(cat "$T/vpd.json")"
  viewer "$D/spot_triangulated.obj" --frames 3 --keys pp --size 64x64 --json -q >"$T/vpp.json"
  grep -F '"renderer": "mesh"' "$T/vpp.json" >/dev/null || fail "p twice does not return to the mesh"
  # the texture is drawn: the spot's black patches and its white skin both appear
  check "$T/m0.png" "any(px(x, y)[0] < 80 for x in range(w) for y in range(h)) and any(px(x, y)[0] > 220 and px(x, y)[:3] != (255, 255, 255) for x in range(w) for y in range(h))"
fi
