# amgsplat sample: methods, texture colours, summary and JSON, errors with exit codes.
source "$(dirname "$0")/common.sh"
"$AMGSPLAT" sample -h | grep "usage: amgsplat sample" >/dev/null || fail "help"
# a textured quad: 4x4 PNG, left half red, right half blue
python3 - "$T" <<'PY'
import struct, zlib, sys
d = sys.argv[1]
rows = b''.join(b'\x00' + b''.join(bytes((255, 0, 0, 255) if x < 2 else (0, 0, 255, 255)) for x in range(4)) for y in range(4))
def chunk(t, b): return struct.pack('>I', len(b)) + t + b + struct.pack('>I', zlib.crc32(t + b) & 0xffffffff)
open(d + '/quad.png', 'wb').write(b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', 4, 4, 8, 6, 0, 0, 0))
                                   + chunk(b'IDAT', zlib.compress(rows)) + chunk(b'IEND', b''))
open(d + '/quad.mtl', 'w').write('newmtl rb\nKd 1 1 1\nmap_Kd quad.png\n')
obj = 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n'
open(d + '/quad.obj', 'w').write('mtllib quad.mtl\nusemtl rb\n' + obj)
open(d + '/bare.obj', 'w').write(obj)
open(d + '/lost.mtl', 'w').write('newmtl skin\nmap_Kd missing/skin.png\n')
open(d + '/lost.obj', 'w').write('mtllib lost.mtl\nusemtl skin\n' + obj)
open(d + '/flat.obj', 'w').write('v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 2 3\n')
open(d + '/tet.off', 'w').write('OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n')
PY
"$AMGSPLAT" sample "$T/quad.obj" --points 5000 -o "$T/quad.xyz" | grep "5000 points (area)" >/dev/null || fail "summary"
python3 - "$T/quad.xyz" <<'PY' || fail "texture colours"
import sys
rows = [list(map(float, l.split())) for l in open(sys.argv[1])]
assert len(rows) == 5000 and len(rows[0]) == 9, (len(rows), rows[0])
for x, y, z, nx, ny, nz, r, g, b in rows:
    assert abs(z) < 1e-6 and abs(nz - 1) < 1e-6
    if 0.13 < x < 0.37: assert (r, g, b) == (255, 0, 0), (x, r, g, b)
    if 0.63 < x < 0.87: assert (r, g, b) == (0, 0, 255), (x, r, g, b)
PY
# --texture gives a bare OBJ the same colours; voxel counts n^2 cells on a flat square
"$AMGSPLAT" sample "$T/bare.obj" --texture "$T/quad.png" -n 2000 -o "$T/bare.ply" --json >"$T/j"
grep -q '"colors": true' "$T/j" || fail "--texture: $(cat "$T/j")"
"$AMGSPLAT" sample "$T/quad.obj" --method voxel --grid 64 -o "$T/vox.ply" --json >"$T/j"
python3 -c "import json,sys; d=json.load(open(sys.argv[1])); assert d['points']==4096 and d['method']=='voxel', d" "$T/j" \
  || fail "voxel count: $(cat "$T/j")"
"$AMGSPLAT" sample "$T/tet.off" --method vertices -o "$T/tet.ply" --json >"$T/j"
python3 -c "import json,sys; d=json.load(open(sys.argv[1])); assert d['points']==4 and d['triangles']==4 and abs(d['area']-(1.5+3**0.5/2))<1e-5, d" "$T/j" \
  || fail "vertices: $(cat "$T/j")"
# deterministic for a seed, and thread count does not matter
"$AMGSPLAT" sample "$T/tet.off" -n 3000 --seed 7 -o "$T/a.ply" -q --threads 1
"$AMGSPLAT" sample "$T/tet.off" -n 3000 --seed 7 -o "$T/b.ply" -q --threads 2
cmp -s "$T/a.ply" "$T/b.ply" || fail "not deterministic across threads"
expect_fail 1 "missing/skin.png" "$AMGSPLAT" sample "$T/lost.obj" -o "$T/x.ply"
grep -q -- "--texture" "$T/err" || fail "missing texture message does not suggest --texture"
expect_fail 1 "zero surface area" "$AMGSPLAT" sample "$T/flat.obj" -o "$T/x.ply"
expect_fail 1 "cannot open '$T/none.obj'" "$AMGSPLAT" sample "$T/none.obj" -o "$T/x.ply"
expect_fail 2 "unknown sampling method 'poisson'" "$AMGSPLAT" sample "$T/quad.obj" --method poisson -o "$T/x.ply"
expect_fail 2 "missing -o" "$AMGSPLAT" sample "$T/quad.obj"
expect_fail 2 "--points must be" "$AMGSPLAT" sample "$T/quad.obj" --points 1 -o "$T/x.ply"
expect_fail 2 "--grid must be" "$AMGSPLAT" sample "$T/quad.obj" --method voxel --grid 0 -o "$T/x.ply"
[[ ! -e "$T/x.ply" ]] || fail "failed runs left an output"
if have_data spot_triangulated.obj spot_texture.png; then
  "$AMGSPLAT" sample "$ASP_TEST_DATA/spot_triangulated.obj" --texture "$ASP_TEST_DATA/spot_texture.png" \
    -n 20000 -o "$T/spot.ply" --json | grep '"colors": true' >/dev/null || fail "spot"
fi
# 3DS through assimp: glmark2-data (a declared dependency, scripts/bootstrap.sh) ships a horse
horse=/usr/share/glmark2/models/horse.3ds
[[ -r $horse ]] || fail "$horse missing: run scripts/bootstrap.sh"
"$AMGSPLAT" sample "$horse" -n 5000 -o "$T/horse.ply" --json >"$T/horse.json"
python3 -c "import json,sys; d=json.load(open(sys.argv[1])); assert d['points']==5000 and d['area']>0, d" "$T/horse.json" \
  || fail "3ds: $(cat "$T/horse.json")"
# a point file given to sample is told what it is
"$AMGSPLAT" sample "$T/quad.obj" -n 200 -o "$T/pts.ply" -q
expect_fail 1 "a point file" "$AMGSPLAT" sample "$T/pts.ply" -o "$T/x.ply"
expect_fail 2 "--up expects" "$AMGSPLAT" sample "$T/quad.obj" --up w -o "$T/x.ply"
# the y-up 3DS horse stands upright (tallest along y: it rears)
"$AMGSPLAT" sample "$horse" -n 5000 -o "$T/horse.ply" -q
"$AMGSPLAT" info --json "$T/horse.ply" | python3 -c "
import json,sys; d=json.load(sys.stdin); e=[b-a for a,b in zip(d['bbox_min'], d['bbox_max'])]
assert e[1] == max(e), e" || fail "3ds horse not upright"
# upper-case extensions for meshes and point output
cp "$T/quad.obj" "$T/QUAD.OBJ"
"$AMGSPLAT" sample "$T/QUAD.OBJ" -n 100 -o "$T/Q.PLY" -q || fail "sample QUAD.OBJ -> Q.PLY"
head -c 3 "$T/Q.PLY" | grep ply >/dev/null || fail "Q.PLY is not a PLY"
echo "sample: ok"
