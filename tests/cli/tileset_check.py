"""What every tileset of `amgsplat export --tiles` must hold, shared by the checks in
tests/cli/export_tiles.sh (streamed ADD tiles, in-memory REPLACE tiles, .dps levels):
  glb(path)           the JSON chunk of a GLB (header checked)
  box_bounds(bv)      an axis-aligned 3D Tiles box as (lo, hi)
  walk(ts, visit)     every tile depth first: refine only on the root, geometricError in
                      [0, the parent's], boxes inside the parent's; visit(tile, lo, hi, depth) per
                      tile; returns the content URIs (each named once)
  files_match(d, u)   the GLBs under d/tiles are exactly the tileset's
  total_bytes(d, u)   bytes of the GLBs and tileset.json
"""
import json
import os
import struct


def glb(path):
    b = open(path, 'rb').read()
    magic, version, length = struct.unpack_from('<4sII', b, 0)
    assert magic == b'glTF' and version == 2 and length == len(b), path
    clen, _ = struct.unpack_from('<II', b, 12)
    return json.loads(b[20:20 + clen])


def box_bounds(bv):
    c, h = bv['box'][:3], bv['box'][3:]
    assert h[1] == h[2] == h[3] == h[5] == h[6] == h[7] == 0, 'boxes are axis-aligned'
    ext = [h[0], h[4], h[8]]
    return [c[k] - ext[k] for k in range(3)], [c[k] + ext[k] for k in range(3)]


def walk(ts, visit):
    uris = []

    def rec(t, parent_error, parent_box, depth):
        assert 'refine' not in t or depth == 0, 'refine is inherited from the root'
        e = t['geometricError']
        assert 0 <= e <= parent_error, f'geometricError grows downwards: {e} > {parent_error}'
        lo, hi = box_bounds(t['boundingVolume'])
        if parent_box:
            plo, phi = parent_box
            for k in range(3):
                assert plo[k] - 1e-6 <= lo[k] and hi[k] <= phi[k] + 1e-6, 'a child box sticks out of its parent'
        uris.append(t['content']['uri'])
        visit(t, lo, hi, depth)
        for c in t.get('children', []):
            rec(c, e, (lo, hi), depth + 1)

    rec(ts['root'], ts['geometricError'], None, 0)
    assert len(set(uris)) == len(uris), 'a GLB is named twice'
    return uris


def files_match(d, uris):
    on_disk = set('tiles/' + f for f in os.listdir(os.path.join(d, 'tiles')))
    assert on_disk == set(uris), f'files not in the tileset: {sorted(on_disk - set(uris))[:5]}'


def total_bytes(d, uris):
    return sum(os.path.getsize(os.path.join(d, u)) for u in uris) + os.path.getsize(os.path.join(d, 'tileset.json'))
