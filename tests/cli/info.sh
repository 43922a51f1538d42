# amgsplat info: a small PLY (counts, attributes, bounds; JSON), meshes (materials, textures found and
# missing, bounds, up axis), images, upper-case names, and errors for bad input.
source "$(dirname "$0")/common.sh"
cat >"$T/tri.ply" <<'PLY'
ply
format ascii 1.0
comment made by info.sh
element vertex 3
property float x
property float y
property float z
property float radius
property uchar quality
end_header
0 0 0 0.5 7
2 0 0 1.5 8
0 4 1 1 9
PLY
"$AMGSPLAT" info "$T/tri.ply" >"$T/out"
grep -q "^points *3$" "$T/out" || fail "point count: $(cat "$T/out")"
grep -q "radii" "$T/out" || fail "radii attribute"
grep -q "quality(uchar)" "$T/out" || fail "extra property"
grep -q "^bbox max *2 4 1$" "$T/out" || fail "bbox: $(cat "$T/out")"
grep -q "radius *mean 1 min 0.5 max 1.5" "$T/out" || fail "radius stats: $(cat "$T/out")"
grep -q "comment *made by info.sh" "$T/out" || fail "comment"
"$AMGSPLAT" info --json "$T/tri.ply" >"$T/json"
python3 -c "import json,sys; d=json.load(open(sys.argv[1])); assert d['points']==3 and d['radii'] and d['bbox_max']==[2,4,1], d" "$T/json" \
  || fail "json: $(cat "$T/json")"
expect_fail 1 "cannot open '$T/missing.ply'" "$AMGSPLAT" info "$T/missing.ply"
expect_fail 2 "expected one file" "$AMGSPLAT" info

# meshes: an OBJ with its .mtl and texture, the same with a texture that is gone, a PLY with faces
python3 - "$T" <<'PY'
import struct, zlib, sys
d = sys.argv[1]
rows = b''.join(b'\x00' + bytes((200, 30, 30)) * 4 for y in range(2))
def chunk(t, b): return struct.pack('>I', len(b)) + t + b + struct.pack('>I', zlib.crc32(t + b) & 0xffffffff)
open(d + '/skin.png', 'wb').write(b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', 4, 2, 8, 2, 0, 0, 0))
                                   + chunk(b'IDAT', zlib.compress(rows)) + chunk(b'IEND', b''))
obj = 'v 0 0 0\nv 2 0 0\nv 2 3 0\nv 0 3 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n'
open(d + '/cow.mtl', 'w').write('newmtl hide\nKd 0.5 0.25 1\nmap_Kd skin.png\n')
open(d + '/cow.obj', 'w').write('mtllib cow.mtl\nusemtl hide\n' + obj)
open(d + '/lost.mtl', 'w').write('newmtl fur\nKd 1 1 1\nmap_Kd textures/fur_gone.png\n')
open(d + '/lost.obj', 'w').write('mtllib lost.mtl\nusemtl fur\n' + obj)
PY
"$AMGSPLAT" info "$T/cow.obj" >"$T/mesh.txt" || fail "info on an OBJ"
grep "^kind *mesh (obj)$" "$T/mesh.txt" >/dev/null || fail "mesh kind: $(cat "$T/mesh.txt")"
grep "^vertices *4$" "$T/mesh.txt" >/dev/null || fail "mesh vertices: $(cat "$T/mesh.txt")"
grep "^faces *2 (triangles)$" "$T/mesh.txt" >/dev/null || fail "mesh faces: $(cat "$T/mesh.txt")"
grep "^uv sets *1$" "$T/mesh.txt" >/dev/null || fail "uv sets"
grep "hide *colour 0.5 0.25 1 1  texture '.*skin.png' 4x2" "$T/mesh.txt" >/dev/null || fail "material: $(cat "$T/mesh.txt")"
grep "^textures *1 found, 0 missing$" "$T/mesh.txt" >/dev/null || fail "textures: $(cat "$T/mesh.txt")"
grep "^bbox max *2 3 0$" "$T/mesh.txt" >/dev/null || fail "mesh bbox: $(cat "$T/mesh.txt")"
grep "^up *y (obj stores no up axis" "$T/mesh.txt" >/dev/null || fail "up axis: $(cat "$T/mesh.txt")"
"$AMGSPLAT" info --json "$T/cow.obj" | python3 -c "
import json,sys; d=json.load(sys.stdin)
assert d['kind']=='mesh' and d['vertices']==4 and d['faces']==2 and d['uv_sets']==1, d
assert d['materials'][0]['name']=='hide' and d['materials'][0]['color']==[0.5,0.25,1,1], d
assert d['textures_found']==1 and d['textures_missing']==[] and d['up']=='y' and d['bbox_max']==[2,3,0], d" \
  || fail "mesh json"
# the missing texture is named, and info still succeeds (sample would fail)
"$AMGSPLAT" info "$T/lost.obj" >"$T/lost.txt" || fail "info on an OBJ with a missing texture must exit 0"
grep "^textures *0 found, 1 missing$" "$T/lost.txt" >/dev/null || fail "missing count: $(cat "$T/lost.txt")"
grep "^missing *.*textures/fur_gone.png (material 'fur')$" "$T/lost.txt" >/dev/null || fail "missing name: $(cat "$T/lost.txt")"
grep "texture MISSING" "$T/lost.txt" >/dev/null || fail "MISSING flag"
"$AMGSPLAT" info --json "$T/lost.obj" | python3 -c "
import json,sys; d=json.load(sys.stdin); assert len(d['textures_missing'])==1 and d['textures_missing'][0].endswith('fur_gone.png'), d" \
  || fail "missing json"
expect_fail 1 "fur_gone.png" "$AMGSPLAT" sample "$T/lost.obj" -o "$T/x.ply"
# a PLY with faces is a mesh; its upper-case twin too
cat >"$T/faces.ply" <<'PLY'
ply
format ascii 1.0
element vertex 4
property float x
property float y
property float z
element face 2
property list uchar int vertex_indices
end_header
0 0 0
1 0 0
1 1 0
0 1 0
3 0 1 2
3 0 2 3
PLY
cp "$T/faces.ply" "$T/FACES.PLY"
for f in faces.ply FACES.PLY; do
  "$AMGSPLAT" info "$T/$f" >"$T/pf.txt" || fail "info $f"
  grep "^kind *mesh (ply)$" "$T/pf.txt" >/dev/null && grep "^faces *2 (triangles)$" "$T/pf.txt" >/dev/null \
    || fail "$f: $(cat "$T/pf.txt")"
done
# upper-case point file and mesh names; an image; a PNG that claims to be a PLY
cp "$T/tri.ply" "$T/TRI.PLY"
"$AMGSPLAT" info "$T/TRI.PLY" | grep "^points *3$" >/dev/null || fail "info TRI.PLY"
cp "$T/cow.obj" "$T/COW.OBJ"
"$AMGSPLAT" info "$T/COW.OBJ" | grep "^vertices *4$" >/dev/null || fail "info COW.OBJ"
"$AMGSPLAT" info "$T/skin.png" >"$T/img.txt"
grep "^size *4x2$" "$T/img.txt" >/dev/null && grep "^channels *3 (RGB)$" "$T/img.txt" >/dev/null || fail "image: $(cat "$T/img.txt")"
cp "$T/skin.png" "$T/liar.ply"
"$AMGSPLAT" info "$T/liar.ply" | grep "^kind *image (png)$" >/dev/null || fail "a PNG named .ply"
# refusals: unknown extension, directory, FIFO (at once, no hang)
echo "1 2 3" >"$T/data.abc"
expect_fail 1 "unknown file type '.abc'" "$AMGSPLAT" info "$T/data.abc"
mkdir -p "$T/dir.ply"
expect_fail 1 "is a directory" "$AMGSPLAT" info "$T/dir.ply"
mkfifo "$T/fifo.obj"
expect_fail 1 "not a regular file" timeout 20 "$AMGSPLAT" info "$T/fifo.obj"
echo "info: ok"
