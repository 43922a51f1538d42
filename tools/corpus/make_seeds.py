#!/usr/bin/env python3
"""Writes the committed seed corpora tools/corpus/<fuzz target>/ (issue #13): small valid inputs of
every format each fuzzer reads, each under 64 KB, all under 1.5 MB. scripts/test.sh stage e seeds
every target from its folder here plus files made fresh by the build (and tests/data/bad).

  tools/corpus/make_seeds.py build/amgsplat build/seed_hier

The .amg, .dps and .hier seeds come from the CLI of a build; everything else is written here byte by
byte (no image library needed). The lead's minimized corpora of the 10-minute runs replace or join
these files when they exist (/tmp/fuzzcorpus/<target>/)."""
import math, os, struct, subprocess, sys, tempfile, zlib

here = os.path.dirname(os.path.abspath(__file__))
amgsplat, seed_hier = sys.argv[1], sys.argv[2]
tmp = tempfile.mkdtemp(prefix='asp-corpus-')


def put(target, name, data):
    d = os.path.join(here, target)
    os.makedirs(d, exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    assert len(data) < 65536, (target, name, len(data))
    with open(os.path.join(d, name), 'wb') as f:
        f.write(data)


def run(*args):
    subprocess.run([amgsplat, *args, '--quiet'], check=True, stdout=subprocess.DEVNULL)


def read(p):
    with open(p, 'rb') as f:
        return f.read()


# ---- point sets: a small octahedron with every attribute (normals, colours, radii, labels)
run('synth', 'octahedron', '--points', '120', '-o', f'{tmp}/oct.ply')
run('convert', '--ascii', f'{tmp}/oct.ply', f'{tmp}/oct_ascii.ply')
run('convert', '--big-endian', f'{tmp}/oct.ply', f'{tmp}/oct_be.ply')
run('convert', f'{tmp}/oct.ply', f'{tmp}/oct.xyz')
run('convert', f'{tmp}/oct.ply', f'{tmp}/oct.pts')
run('synth', 'sphere', '--points', '200', '-o', f'{tmp}/sphere.ply')

ply_mesh_ascii = ('ply\nformat ascii 1.0\ncomment a tetrahedron\nelement vertex 4\nproperty float x\n'
                  'property float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n'
                  'element face 4\nproperty list uchar int vertex_indices\nend_header\n'
                  '0 0 0 255 0 0\n1 0 0 0 255 0\n0 1 0 0 0 255\n0 0 1 255 255 255\n3 0 1 2\n3 0 1 3\n3 0 2 3\n3 1 2 3\n')
verts = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
faces = [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)]
ply_mesh_bin = (b'ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\n'
                b'property float z\nelement face 4\nproperty list uchar uint vertex_indices\nend_header\n'
                + b''.join(struct.pack('<3f', *v) for v in verts)
                + b''.join(struct.pack('<B3I', 3, *f) for f in faces))
ply_strips = ('ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\nproperty float z\n'
              'element tristrips 1\nproperty list int int vertex_indices\nend_header\n'
              '0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 2 0\n1 2 0\n9 0 1 2 3 -1 2 3 4 5\n')
ply_extra = ('ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\nproperty double z\n'
             'property float nx\nproperty float ny\nproperty float nz\nproperty float radius\nproperty float u\n'
             'property float v\nproperty int label\nproperty short quality\nend_header\n'
             '0 0 0 0 0 1 0.1 0 0 1 7\n1 0 0 0 0 1 0.1 1 0 2 8\n0 1 0 0 0 1 0.1 0 1 3 9\n')

for t in ('fuzz_ply', 'fuzz_file_kind'):
    put(t, 'oct_le.ply', read(f'{tmp}/oct.ply'))
    put(t, 'oct_ascii.ply', read(f'{tmp}/oct_ascii.ply'))
    put(t, 'oct_be.ply', read(f'{tmp}/oct_be.ply'))
    put(t, 'tet_ascii.ply', ply_mesh_ascii)
    put(t, 'tet_le.ply', ply_mesh_bin)
    put(t, 'strips.ply', ply_strips)
    put(t, 'extra.ply', ply_extra)
    put(t, 'oct.xyz', read(f'{tmp}/oct.xyz'))

xyz_crlf = '0 0 0\r\n1 0 0\r\n0 1 0\r\n0 0 1\r\n'
xyz_cr = '0 0 0\r1 0 0\r0 1 0\r0 0 1\r'
xyz_normals = '# x y z nx ny nz r g b\n0 0 0 0 0 1 255 0 0\n1 0 0 0 0 1 0 255 0\n0 1 0 0 0 1 0 0 255\n'
pts = '4\n0 0 0 -500 255 0 0\n1 0 0 -400 0 255 0\n0 1 0 -300 0 0 255\n0 0 1 -200 255 255 255\n'
for t in ('fuzz_xyz', 'fuzz_file_kind', 'fuzz_ply'):
    put(t, 'crlf.xyz', xyz_crlf)
    put(t, 'cr.xyz', xyz_cr)
    put(t, 'normals_colours.xyz', xyz_normals)
    put(t, 'count.pts', pts)
put('fuzz_xyz', 'oct.xyz', read(f'{tmp}/oct.xyz'))
put('fuzz_xyz', 'oct.pts', read(f'{tmp}/oct.pts'))
put('fuzz_xyz', 'sci.txt', '1e-3 2.5E+2 -0.0\n.5 -.5 5.\n-1e+2 7 0.25\n')

# ---- .amg, .dps, .hier from the CLI
run('decompose', f'{tmp}/sphere.ply', '-o', f'{tmp}/sphere.amg')
run('decompose', f'{tmp}/oct.ply', '-o', f'{tmp}/oct.amg')
subprocess.run([amgsplat, 'build', f'{tmp}/sphere.amg', '-o', f'{tmp}/sphere.dps', '--primitives', '6',
                '--max-texture', '16', '--quiet'], check=True, stdout=subprocess.DEVNULL)
subprocess.run([seed_hier, f'{tmp}/oct.ply', f'{tmp}/oct.hier'], check=True, stdout=subprocess.DEVNULL)
put('fuzz_amg', 'sphere.amg', read(f'{tmp}/sphere.amg'))
put('fuzz_amg', 'oct_attrs.amg', read(f'{tmp}/oct.amg'))
put('fuzz_dps', 'sphere.dps', read(f'{tmp}/sphere.dps'))
put('fuzz_hier', 'oct.hier', read(f'{tmp}/oct.hier'))
for n, src in (('sphere.amg', 'sphere.amg'), ('sphere.dps', 'sphere.dps'), ('oct.hier', 'oct.hier')):
    put('fuzz_file_kind', n, read(f'{tmp}/{src}')[:4096])


# ---- images: PNG written here; JPEG, TGA and BMP by stb_image_write through a tiny helper if cc exists
def png(w, h, colour_type, rows, bit_depth=8):
    def chunk(t, b):
        return struct.pack('>I', len(b)) + t + b + struct.pack('>I', zlib.crc32(t + b) & 0xffffffff)
    raw = b''.join(b'\x00' + r for r in rows)
    return (b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', w, h, bit_depth, colour_type, 0, 0, 0))
            + chunk(b'IDAT', zlib.compress(raw)) + chunk(b'IEND', b''))


put('fuzz_image', 'rgb_2x2.png', png(2, 2, 2, [b'\xff\x00\x00\x00\xff\x00', b'\x00\x00\xff\xff\xff\xff']))
put('fuzz_image', 'rgba_4x4.png', png(4, 4, 6, [bytes(sum(([x * 60, y * 60, 128, 255 - x * 40] for x in range(4)), []))
                                                 for y in range(4)]))
put('fuzz_image', 'grey_8x8.png', png(8, 8, 0, [bytes(range(y * 8, y * 8 + 8)) for y in range(8)]))
put('fuzz_image', 'grey16_2x2.png', png(2, 2, 0, [b'\x00\x01\xff\xfe', b'\x80\x00\x7f\xff'], bit_depth=16))
put('fuzz_image', 'tiny.gif', b'GIF89a\x01\x00\x01\x00\x80\x00\x00\xff\xff\xff\x00\x00\x00!\xf9\x04\x01\x00\x00\x00'
                               b'\x00,\x00\x00\x00\x00\x01\x00\x01\x00\x00\x02\x02D\x01\x00;')
helper = os.path.join(tmp, 'imgs')
src = helper + '.c'
with open(src, 'w') as f:
    f.write('#define STB_IMAGE_WRITE_IMPLEMENTATION\n#include <stb/stb_image_write.h>\n'
            'int main(int c, char **v) { unsigned char p[192], g[256]; (void)c;\n'
            ' for (int i = 0; i < 64; i++) { p[3*i] = (unsigned char)(i*4); p[3*i+1] = (unsigned char)(255-i*4);'
            ' p[3*i+2] = (unsigned char)((i%8)*32); }\n for (int i = 0; i < 256; i++) g[i] = (unsigned char)i;\n'
            ' return !(stbi_write_jpg(v[1], 8, 8, 3, p, 90) && stbi_write_jpg(v[2], 16, 16, 1, g, 50) &&'
            ' stbi_write_tga(v[3], 8, 8, 3, p) && stbi_write_bmp(v[4], 8, 8, 3, p)); }\n')
if subprocess.run(['cc', '-O1', '-o', helper, src, '-lm']).returncode == 0:
    names = ['rgb_8x8.jpg', 'grey_16x16.jpg', 'rgb_8x8.tga', 'rgb_8x8.bmp']
    subprocess.run([helper] + [f'{tmp}/{n}' for n in names], check=True)
    for n in names:
        put('fuzz_image', n, read(f'{tmp}/{n}'))
for n in ('rgb_2x2.png', 'tiny.gif'):
    put('fuzz_file_kind', n, read(os.path.join(here, 'fuzz_image', n)))

# ---- meshes for fuzz_mesh: the first byte picks the extension (0 off, 1 obj, 2 stl, 3 ply, 4 3ds, 5 gltf)
off = 'OFF\n4 4 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 1 3\n3 0 2 3\n4 1 2 3 0\n'
obj = ('# a textured quad and a triangle\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvt 1 0\nvt 1 1\n'
       'vt 0 1\nvn 0 0 1\ng quad\nusemtl none\nf 1/1/1 2/2/1 3/3/1 4/4/1\no tri\nf -5//1 -4//1 -1//1\n')
stl_ascii = ('solid tet\n' + ''.join('facet normal 0 0 0\n outer loop\n' + ''.join(
    ' vertex %g %g %g\n' % verts[i] for i in f) + ' endloop\nendfacet\n' for f in faces) + 'endsolid tet\n')
stl_bin = (b'binary stl'.ljust(80, b' ') + struct.pack('<I', len(faces)) + b''.join(
    struct.pack('<3f', 0, 0, 0) + b''.join(struct.pack('<3f', *verts[i]) for i in f) + b'\x00\x00' for f in faces))
gltf = ('{"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],'
        '"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],'
        '"buffers":[{"byteLength":42,"uri":"data:application/octet-stream;base64,'
        'AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIA"}],'
        '"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":6}],'
        '"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","max":[1,1,0],"min":[0,0,0]},'
        '{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}]}\n')
put('fuzz_mesh', 'tet.off', b'\x00' + off.encode())
put('fuzz_mesh', 'quad_tri.obj', b'\x01' + obj.encode())
put('fuzz_mesh', 'tet_ascii.stl', b'\x02' + stl_ascii.encode())
put('fuzz_mesh', 'tet_binary.stl', b'\x02' + stl_bin)
put('fuzz_mesh', 'tet_ascii.ply', b'\x03' + ply_mesh_ascii.encode())
put('fuzz_mesh', 'tet_le.ply', b'\x03' + ply_mesh_bin)
put('fuzz_mesh', 'strips.ply', b'\x03' + ply_strips.encode())
put('fuzz_mesh', 'tri.gltf', b'\x05' + gltf.encode())
for n, d in (('tet.off', off), ('quad_tri.obj', obj), ('tet_ascii.stl', stl_ascii)):
    put('fuzz_file_kind', n, d)
put('fuzz_file_kind', 'tet_binary.stl', stl_bin)

# ---- fuzz_mesh_simplify: counts byte by byte, then float bits, indices and material ids
def simplify_seed(nv, nt, nm, flags, target, finite, pos, tris, mats):
    return (bytes([(nv - 1) % 64, (nt - 1) % 96, (nm - 1) % 3, flags, target, finite])
            + b''.join(struct.pack('<f', c) for c in pos) + bytes(tris) + bytes(mats))
grid = [(x, y, 0.1 * ((x * y) % 3)) for y in range(5) for x in range(5)]
tris = []
for y in range(4):
    for x in range(4):
        a = y * 5 + x
        tris += [a, a + 1, a + 6, a, a + 6, a + 5]
pos = [c for p in grid for c in p]
put('fuzz_mesh_simplify', 'grid_5x5.bin', simplify_seed(25, 32, 1, 0, 8, 1, pos, tris, [0] * 32))
put('fuzz_mesh_simplify', 'grid_two_materials.bin',
    simplify_seed(25, 32, 2, 7, 4, 1, pos, tris, [t % 2 for t in range(32)]))
put('fuzz_mesh_simplify', 'tet_raw.bin',
    simplify_seed(4, 4, 1, 1, 1, 0, [c for v in verts for c in v], [i for f in faces for i in f], [0] * 4))


# ---- the batched point reader and the streamed .hier (issue 28): terrain from the CLI as binary PLY
# (little and big endian), LAS from the CLI (formats 0, 7) and tests/cli/las_handmade.py (1.2-1.4,
# formats 1, 3, 8), PLYs of other number types written here, and converted .hier files of 25 nodes
run('synth', 'terrain', '--points', '2000', '-o', f'{tmp}/terrain.ply')
run('convert', '--big-endian', f'{tmp}/terrain.ply', f'{tmp}/terrain_be.ply')
put('fuzz_point_stream', 'terrain.ply', read(f'{tmp}/terrain.ply'))
put('fuzz_point_stream', 'terrain_be.ply', read(f'{tmp}/terrain_be.ply'))
run('synth', 'octahedron', '--points', '400', '-o', f'{tmp}/oct400.ply')
put('fuzz_point_stream', 'oct_props.ply', read(f'{tmp}/oct400.ply'))
for fmt in (0, 7):
    run('convert', '--las-format', str(fmt), f'{tmp}/oct400.ply', f'{tmp}/oct_f{fmt}.las')
    put('fuzz_point_stream', f'oct_f{fmt}.las', read(f'{tmp}/oct_f{fmt}.las'))
las_handmade = os.path.join(here, '..', '..', 'tests', 'cli', 'las_handmade.py')
for name, minor, fmt, extra in (('hand12_f1', 2, 1, []), ('hand13_f3', 3, 3, []), ('hand14_f8', 4, 8, ['--extra'])):
    subprocess.run([sys.executable, las_handmade, f'{tmp}/{name}.las', str(minor), str(fmt), '200', *extra],
                   check=True, stdout=subprocess.DEVNULL)
    put('fuzz_point_stream', f'{name}.las', read(f'{tmp}/{name}.las'))


def vertex_ply(fmt, props, rows, before='', after=''):
    e = '<' if fmt == 'binary_little_endian' else '>'
    h = f'ply\nformat {fmt} 1.0\n{before}element vertex {len(rows)}\n'
    h += ''.join(f'property {t} {n}\n' for t, n, _ in props) + after + 'end_header\n'
    return h.encode() + b''.join(struct.pack(e + ''.join(c for _, _, c in props), *r) for r in rows)


put('fuzz_point_stream', 'double_rgba_be.ply', vertex_ply(
    'binary_big_endian', [('double', 'x', 'd'), ('double', 'y', 'd'), ('double', 'z', 'd'), ('uchar', 'red', 'B'),
                          ('uchar', 'green', 'B'), ('uchar', 'blue', 'B'), ('uchar', 'alpha', 'B')],
    [(math.cos(i * .1), math.sin(i * .1), i * .01, i % 256, 3 * i % 256, 7 * i % 256, 200) for i in range(60)]))
put('fuzz_point_stream', 'int16_faces.ply', vertex_ply(
    'binary_little_endian', [('short', 'x', 'h'), ('int', 'y', 'i'), ('ushort', 'z', 'H'), ('float', 'confidence', 'f'),
                             ('uint8', 'red', 'B')],
    [(i, -i, 2 * i, 0.5, i % 256) for i in range(60)],
    before='comment empty element first\nelement camera 0\nproperty float f\n',
    after='element face 0\nproperty list uchar int vertex_indices\n'))
run('convert', f'{tmp}/terrain.ply', '-o', f'{tmp}/terrain.hier', '--memory', '64M', '--node-points', '256')
put('fuzz_ooc', 'terrain.hier', read(f'{tmp}/terrain.hier'))
run('synth', 'terrain', '--points', '600', '-o', f'{tmp}/t600.ply')
run('convert', f'{tmp}/t600.ply', '-o', f'{tmp}/terrain600.hier', '--memory', '64M', '--node-points', '64')
put('fuzz_ooc', 'terrain600.hier', read(f'{tmp}/terrain600.hier'))

total = sum(os.path.getsize(os.path.join(dp, f)) for dp, _, fs in os.walk(here) for f in fs
            if not f.endswith(('.py', '.md')))
print(f'corpus: {total} bytes')
assert total < 1.5e6
