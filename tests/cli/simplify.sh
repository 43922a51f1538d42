# amgsplat simplify: target counts, OBJ/PLY output that reads back with its texture, the printed
# numbers (triangles, vertices, error, GPU bytes), and clear messages for bad options.
source "$(dirname "$0")/common.sh"
"$AMGSPLAT" simplify -h | grep "usage: amgsplat simplify" >/dev/null || fail "help"
# an octahedron-like closed mesh with UVs and a texture: a subdivided cube (6 x 8 x 8 quads, 768 triangles)
python3 - "$T" <<'PY'
import struct, zlib, sys
d = sys.argv[1]
rows = b''.join(b'\x00' + b''.join(bytes(((x * 37) % 256, (y * 59) % 256, 128, 255)) for x in range(8)) for y in range(8))
def chunk(t, b): return struct.pack('>I', len(b)) + t + b + struct.pack('>I', zlib.crc32(t + b) & 0xffffffff)
open(d + '/cube.png', 'wb').write(b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', 8, 8, 8, 6, 0, 0, 0))
                                   + chunk(b'IDAT', zlib.compress(rows)) + chunk(b'IEND', b''))
open(d + '/cube.mtl', 'w').write('newmtl tex\nKd 1 1 1\nmap_Kd cube.png\n')
n = 8; v = []; vt = []; f = []
for axis in range(3):
    for side in (-1, 1):
        base = len(v)
        for i in range(n + 1):
            for j in range(n + 1):
                a, b = -1 + 2 * i / n, -1 + 2 * j / n
                p = [0, 0, 0]; p[axis] = side; p[(axis + 1) % 3] = a; p[(axis + 2) % 3] = b
                v.append(p); vt.append((i / n, j / n))
        for i in range(n):
            for j in range(n):
                q = [base + i * (n + 1) + j, base + (i + 1) * (n + 1) + j, base + (i + 1) * (n + 1) + j + 1, base + i * (n + 1) + j + 1]
                if side < 0: q.reverse()
                f.append((q[0], q[1], q[2])); f.append((q[0], q[2], q[3]))
with open(d + '/cube.obj', 'w') as o:
    o.write('mtllib cube.mtl\nusemtl tex\n')
    for p in v: o.write('v %g %g %g\n' % tuple(p))
    for t in vt: o.write('vt %g %g\n' % t)
    for t in f: o.write('f %d/%d %d/%d %d/%d\n' % (t[0] + 1, t[0] + 1, t[1] + 1, t[1] + 1, t[2] + 1, t[2] + 1))
PY
"$AMGSPLAT" simplify "$T/cube.obj" --triangles 100 -o "$T/c.obj" --json >"$T/j"
python3 - "$T/j" <<'PY' || fail "cube json: $(cat "$T/j")"
import json, sys
d = json.load(open(sys.argv[1]))
assert d['input_triangles'] == 768 and d['target_triangles'] == 100, d
assert 12 <= d['triangles'] <= 105, d
b = d['bytes']
# 32 bytes per vertex (position, normal, uv), 12 per triangle, 8x8 RGBA8 with mipmaps = 341
assert b['vertex'] == 32 * d['vertices'] and b['index'] == 12 * d['triangles'] and b['texture'] == 341, b
assert b['total'] == b['vertex'] + b['index'] + b['texture'] and d['bytes']['total'] < d['input_bytes']['total'], d
assert 0 <= d['error'] < 0.01, d   # a flat-sided cube simplifies without error
PY
[[ -s "$T/c.mtl" && -s "$T/c.png" ]] || fail "OBJ output lacks its .mtl or .png"
"$AMGSPLAT" info "$T/c.obj" >"$T/info"
grep "c.png' 8x8" "$T/info" >/dev/null || fail "texture not named in the OBJ output: $(cat "$T/info")"
# PLY output reads back with the same counts and its texture
"$AMGSPLAT" simplify "$T/cube.obj" -n 100 -o "$T/c.ply" --json >"$T/jp"
python3 - "$T/j" "$T/jp" <<'PY' || fail "ply json"
import json, sys
a, b = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
assert a['triangles'] == b['triangles'] and a['vertices'] == b['vertices'], (a, b)
PY
"$AMGSPLAT" info "$T/c.ply" >"$T/info"
grep "c.png' 8x8" "$T/info" >/dev/null || fail "PLY texture: $(cat "$T/info")"
tris=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['triangles'])" "$T/jp")
grep -E "^faces +$tris " "$T/info" >/dev/null || fail "PLY reads back with other counts: $(cat "$T/info")"
# the text summary
"$AMGSPLAT" simplify "$T/cube.obj" -n 200 -o "$T/d.obj" >"$T/out"
grep "768 -> .* triangles (target 200)" "$T/out" >/dev/null || fail "summary: $(cat "$T/out")"
grep "^GPU bytes " "$T/out" >/dev/null || fail "summary bytes: $(cat "$T/out")"
# bad options: clear messages, exit 2, no output left
expect_fail 2 "missing -o" "$AMGSPLAT" simplify "$T/cube.obj" -n 10
expect_fail 2 "missing --triangles" "$AMGSPLAT" simplify "$T/cube.obj" -o "$T/x.obj"
expect_fail 2 "--triangles must be 1 to 767 ('$T/cube.obj' has 768 triangles), got 768" \
  "$AMGSPLAT" simplify "$T/cube.obj" -n 768 -o "$T/x.obj"
expect_fail 2 "--triangles expects a non-negative integer, got '-5'" "$AMGSPLAT" simplify "$T/cube.obj" -n -5 -o "$T/x.obj"
expect_fail 2 "must end in .obj or .ply" "$AMGSPLAT" simplify "$T/cube.obj" -n 10 -o "$T/x.stl"
expect_fail 2 "--error must be in 0..1" "$AMGSPLAT" simplify "$T/cube.obj" -n 10 --error 2 -o "$T/x.obj"
expect_fail 1 "cannot open '$T/none.obj'" "$AMGSPLAT" simplify "$T/none.obj" -n 10 -o "$T/x.obj"
[[ ! -e "$T/x.obj" && ! -e "$T/x.stl" ]] || fail "failed runs left an output"
# the bunny at 1000 triangles lands within 5% of the target
bunny="$ASP_TEST_DATA/stanford-bunny.obj"
[[ -r $bunny ]] || bunny=/usr/share/glmark2/models/bunny.obj
if [[ -r $bunny ]]; then
  "$AMGSPLAT" simplify "$bunny" --triangles 1000 -o "$T/bunny.ply" --json >"$T/jb"
  python3 -c "import json,sys; d=json.load(open(sys.argv[1])); assert abs(d['triangles']-1000) <= 50 and not d['short_of_target'] and d['error'] < 0.02, d" "$T/jb" \
    || fail "bunny: $(cat "$T/jb")"
  echo "bunny: $(python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(d['input_triangles'], '->', d['triangles'], 'triangles, error', d['error'])" "$T/jb")"
else
  have_data stanford-bunny.obj || true
fi
# the textured spot keeps its texture: sampled points of the simplified mesh look like the original's
if have_data spot_triangulated.obj spot_texture.png; then
  "$AMGSPLAT" simplify "$ASP_TEST_DATA/spot_triangulated.obj" --texture "$ASP_TEST_DATA/spot_texture.png" \
    --triangles 1000 -o "$T/spot.obj" -q
  "$AMGSPLAT" info "$T/spot.obj" | grep "/spot.png' 1024x1024" >/dev/null || fail "spot texture lost"
  "$AMGSPLAT" sample "$ASP_TEST_DATA/spot_triangulated.obj" --texture "$ASP_TEST_DATA/spot_texture.png" \
    -n 100000 -o "$T/spot_full.ply" -q
  "$AMGSPLAT" sample "$T/spot.obj" -n 100000 -o "$T/spot_simple.ply" -q
  "$AMGSPLAT" render "$T/spot_full.ply" -o "$T/full.png" --size 128x128 --views 4 -q
  "$AMGSPLAT" render "$T/spot_simple.ply" -o "$T/simple.png" --size 128x128 --views 4 -q
  "$AMGSPLAT" imgdiff "$T/full.png" "$T/simple.png" --json >"$T/jd"
  python3 -c "import json,sys; d=json.load(open(sys.argv[1])); assert d['ssim'] > 0.9 and d['iou'] > 0.95, d" "$T/jd" \
    || fail "spot simplified looks different: $(cat "$T/jd")"
fi
