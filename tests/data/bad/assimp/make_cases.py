#!/usr/bin/env python3
"""Makes the Collada, glTF/GLB and 3DS cases of issue #31 (tests/cli/hostile_assimp.sh reads them):
a valid file of each format (ok_*) and one file per lie that crashed assimp, made it allocate
gigabytes or read out of bounds before the pre-checks. Run from this folder; deterministic."""
import base64, json, struct, sys, os

out = os.path.dirname(os.path.abspath(__file__)) if len(sys.argv) < 2 else sys.argv[1]

def write(name, data):
    with open(os.path.join(out, name), 'wb') as f:
        f.write(data if isinstance(data, bytes) else data.encode())

# ---- Collada: one triangle ----
DAE = '''<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="meter" meter="1"/><up_axis>Y_UP</up_axis></asset>
  <library_geometries>
    <geometry id="tri" name="tri">
      <mesh>
        <source id="pos">
          <float_array id="pos-array" count="{fcount}">{floats}</float_array>
          <technique_common>
            <accessor source="#pos-array" count="{acount}" stride="3">
              <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
            </accessor>
          </technique_common>
        </source>
        <vertices id="verts"><input semantic="POSITION" source="#pos"/></vertices>
        <{prim} count="{pcount}">
          <input semantic="VERTEX" source="#verts" offset="0"/>{vcount}
          <p>{p}</p>
        </{prim}>
      </mesh>
    </geometry>
  </library_geometries>
  <library_visual_scenes>
    <visual_scene id="scene"><node id="n"><instance_geometry url="#tri"/></node></visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
'''
def dae(fcount=9, floats='0 0 0 1 0 0 0 1 0', acount=3, prim='triangles', pcount=1, p='0 1 2', vcount=''):
    return DAE.format(fcount=fcount, floats=floats, acount=acount, prim=prim, pcount=pcount, p=p, vcount=vcount)

write('ok_tri.dae', dae())
write('dae_count_negative.dae', dae(fcount=-1))
write('dae_token_deleted.dae', dae(floats='0 0 0 1 0 0 0 1'))
write('dae_huge_count.dae', dae(fcount=999999999, acount=333333333))
write('dae_accessor_past.dae', dae(acount=4))
write('dae_index_past.dae', dae(p='0 1 7'))
write('dae_p_short.dae', dae(pcount=2))
write('dae_polylist_vcount.dae', dae(prim='polylist', pcount=2, vcount='\n          <vcount>3</vcount>'))
write('dae_cut.dae', dae()[:700])

# ---- glTF 2.0: one triangle, positions (36 bytes) and indices (6 bytes + 2 padding) in one buffer ----
pos = struct.pack('<9f', 0, 0, 0, 1, 0, 0, 0, 1, 0)
idx = struct.pack('<3H', 0, 1, 2) + b'\0\0'
def gltf(bin_uri=True, view_len=36, sparse=None, cycle=False, buffer_len=None):
    blob = pos + idx
    g = {
        'asset': {'version': '2.0'},
        'scene': 0, 'scenes': [{'nodes': [0]}],
        'nodes': [{'mesh': 0}],
        'meshes': [{'primitives': [{'attributes': {'POSITION': 0}, 'indices': 1}]}],
        'buffers': [{'byteLength': buffer_len or len(blob)}],
        'bufferViews': [{'buffer': 0, 'byteOffset': 0, 'byteLength': view_len},
                        {'buffer': 0, 'byteOffset': 36, 'byteLength': 6}],
        'accessors': [{'bufferView': 0, 'componentType': 5126, 'count': 3, 'type': 'VEC3',
                       'min': [0, 0, 0], 'max': [1, 1, 0]},
                      {'bufferView': 1, 'componentType': 5123, 'count': 3, 'type': 'SCALAR'}],
    }
    if sparse:
        # one sparse entry: index (uint16) then a replacement VEC3 in a third view
        sblob = struct.pack('<H', sparse) + b'\0\0' + struct.pack('<3f', 0, 0, 1)
        blob += sblob
        g['buffers'][0]['byteLength'] = len(blob)
        g['bufferViews'] += [{'buffer': 0, 'byteOffset': 44, 'byteLength': 2},
                             {'buffer': 0, 'byteOffset': 48, 'byteLength': 12}]
        g['accessors'][0]['sparse'] = {'count': 1, 'indices': {'bufferView': 2, 'componentType': 5123},
                                       'values': {'bufferView': 3}}
    if cycle:
        g['nodes'] = [{'mesh': 0, 'children': [1]}, {'children': [0]}]
    if bin_uri:
        g['buffers'][0]['uri'] = 'data:application/octet-stream;base64,' + base64.b64encode(blob).decode()
    return g, blob

def glb(g, blob, header_len=None, json_len=None):
    j = json.dumps(g).encode()
    j += b' ' * (-len(j) % 4)
    blob += b'\0' * (-len(blob) % 4)
    body = struct.pack('<II', json_len if json_len is not None else len(j), 0x4E4F534A) + j
    body += struct.pack('<II', len(blob), 0x004E4942) + blob
    return b'glTF' + struct.pack('<II', 2, header_len if header_len is not None else 12 + len(body)) + body

write('ok_tri.gltf', json.dumps(gltf()[0]))
write('ok_tri.glb', glb(*gltf(bin_uri=False)))
write('ok_sparse.gltf', json.dumps(gltf(sparse=2)[0]))
write('gltf_sparse_past.gltf', json.dumps(gltf(sparse=40000)[0]))
write('gltf_view_past.gltf', json.dumps(gltf(view_len=400)[0]))
write('gltf_buffer_lies.gltf', json.dumps(gltf(buffer_len=4000)[0]))
write('gltf_node_cycle.gltf', json.dumps(gltf(cycle=True)[0]))
write('glb_json_length.glb', glb(*gltf(bin_uri=False), json_len=0xFFFFFFFF))
write('glb_header_length.glb', glb(*gltf(bin_uri=False), header_len=0xFFFFFFFF))
write('glb_cut.glb', glb(*gltf(bin_uri=False))[:-20])

# ---- 3DS: main > editor > object "tri" > trimesh > vertex list, face list ----
def chunk(cid, body):
    return struct.pack('<HI', cid, 6 + len(body)) + body
def tds(nverts=3, faces=((0, 1, 2),), vcount=None, fix=None):
    verts = struct.pack('<H', vcount if vcount is not None else nverts) + pos[:12 * nverts]
    fl = struct.pack('<H', len(faces)) + b''.join(struct.pack('<4H', a, b, c, 0) for a, b, c in faces)
    mesh = chunk(0x4100, chunk(0x4110, verts) + chunk(0x4120, fl))
    data = chunk(0x4D4D, chunk(0x0002, struct.pack('<I', 3)) + chunk(0x3D3D, chunk(0x4000, b'tri\0' + mesh)))
    return fix(data) if fix else data

write('ok_tri.3ds', tds())
write('3ds_vertex_count.3ds', tds(vcount=5000))
write('3ds_face_index.3ds', tds(faces=((0, 1, 9),)))
write('3ds_chunk_past.3ds', tds(fix=lambda d: d[:2] + struct.pack('<I', 0x7fffffff) + d[6:]))
write('3ds_cut.3ds', tds()[:-7])
