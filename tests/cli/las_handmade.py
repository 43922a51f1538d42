#!/usr/bin/env python3
"""Writes a LAS file byte by byte from the ASPRS LAS 1.4 R15 tables (header Table 3,
VLR Table 4, point formats Tables 7-17, Extra Bytes Table 24), independent of
amgsplat's writer, and prints what it holds as JSON: the true world coordinate
of every point (from the integers), the 16-bit colours and the other fields.

usage: las_handmade.py OUT.las VERSION_MINOR FORMAT [N] [--extra] [--crs]

--crs adds the CRS VLRs of LAS 1.4 2.5 (user LASF_Projection): an OGC WKT (record 2112) and
GeoTIFF keys (34735) naming EPSG:32633 (WGS 84 / UTM zone 33N) and vertical EPSG:5703.
"""
import json
import math
import struct
import sys

FORMAT_SIZE = {0: 20, 1: 28, 2: 26, 3: 34, 6: 30, 7: 36, 8: 38}
SCALE = (0.001, 0.001, 0.001)
OFFSET = (500000.0, 5000000.0, 300.0)  # UTM-size easting/northing, a terrain height


def points(n):
    """Deterministic points: a 1.2 km x 0.8 km x 90 m patch around the offset, integers as LAS stores them."""
    out = []
    for i in range(n):
        t = i / max(n - 1, 1)
        X = int(round(-600000 + 1200000 * t + 1234 * math.sin(7 * i)))
        Y = int(round(-400000 + 800000 * ((i * 7919) % n) / n))
        Z = int(round(45000 * math.cos(3 * t) + (i % 13)))
        rgb = ((i * 997) % 65536, (i * 6007 + 300) % 65536, 65535 - (i * 131) % 65536)
        out.append(dict(X=X, Y=Y, Z=Z, intensity=(i * 37) % 65536, ret=1 + i % 3, nret=3,
                        cls=(2, 5, 6, 9)[i % 4], user=i % 256, psid=(i * 3) % 65536,
                        gps=1.0e8 + 0.25 * i, rgb=rgb, nir=(i * 17) % 65536, angle=(i % 61) - 30,
                        height=float(i) * 0.5))
    return out


def record(fmt, p, extra):
    if fmt < 6:
        b = struct.pack('<iiiHBBbBH', p['X'], p['Y'], p['Z'], p['intensity'],
                        (p['ret'] & 7) | (p['nret'] & 7) << 3, p['cls'] & 31, p['angle'], p['user'], p['psid'])
        if fmt in (1, 3):
            b += struct.pack('<d', p['gps'])
        if fmt in (2, 3):
            b += struct.pack('<HHH', *p['rgb'])
    else:
        b = struct.pack('<iiiHBBBBhHd', p['X'], p['Y'], p['Z'], p['intensity'],
                        (p['ret'] & 15) | (p['nret'] & 15) << 4, 0, p['cls'], p['user'],
                        int(round(p['angle'] / 0.006)), p['psid'], p['gps'])
        if fmt in (7, 8):
            b += struct.pack('<HHH', *p['rgb'])
        if fmt == 8:
            b += struct.pack('<H', p['nir'])
    assert len(b) == FORMAT_SIZE[fmt]
    if extra:
        b += struct.pack('<f', p['height'])
    return b


def extra_bytes_vlr():
    d = bytearray(192)
    d[2] = 9  # float
    d[4:4 + 6] = b'height'
    d[160:160 + 11] = b'test height'
    return struct.pack('<H16sHH32s', 0, b'LASF_Spec', 4, 192, b'Extra Bytes') + bytes(d)


WKT = ('PROJCS["WGS 84 / UTM zone 33N",GEOGCS["WGS 84",DATUM["WGS_1984",SPHEROID["WGS 84",6378137,'
       '298.257223563]],PRIMEM["Greenwich",0],UNIT["degree",0.0174532925199433]],PROJECTION["Transverse_Mercator"],'
       'PARAMETER["central_meridian",15],PARAMETER["scale_factor",0.9996],PARAMETER["false_easting",500000],'
       'UNIT["metre",1],AUTHORITY["EPSG","32633"]]')


def crs_vlrs():
    wkt = WKT.encode() + b'\0'
    keys = struct.pack('<16H', 1, 1, 0, 3, 1024, 0, 1, 1, 3072, 0, 1, 32633, 4096, 0, 1, 5703)
    return (struct.pack('<H16sHH32s', 0, b'LASF_Projection', 2112, len(wkt), b'OGC WKT') + wkt +
            struct.pack('<H16sHH32s', 0, b'LASF_Projection', 34735, len(keys), b'GeoKeyDirectoryTag') + keys)


def main():
    path, minor, fmt = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    n = int(sys.argv[4]) if len(sys.argv) > 4 and not sys.argv[4].startswith('--') else 1000
    extra = '--extra' in sys.argv
    crs = '--crs' in sys.argv
    pts = points(n)
    header_size = {2: 227, 3: 235, 4: 375}[minor]
    vlrs = (extra_bytes_vlr() if extra else b'') + (crs_vlrs() if crs else b'')
    reclen = FORMAT_SIZE[fmt] + (4 if extra else 0)
    body = b''.join(record(fmt, p, extra) for p in pts)
    world = [[OFFSET[k] + SCALE[k] * p['XYZ'[k]] for k in range(3)] for p in pts]
    lo = [min(w[k] for w in world) for k in range(3)]
    hi = [max(w[k] for w in world) for k in range(3)]
    by_return = [sum(1 for p in pts if p['ret'] == r + 1) for r in range(15)]
    legacy = fmt < 6
    h = bytearray(header_size)
    struct.pack_into('<4sHH16sBB32s32sHHHIIBHI', h, 0, b'LASF', 7, 0, bytes(range(16)), 1, minor,
                     b'hand-built', b'las_handmade.py', 200, 2024, header_size, header_size + len(vlrs),
                     (1 if extra else 0) + (2 if crs else 0), fmt, reclen, n if legacy else 0)
    struct.pack_into('<5I', h, 111, *[c if legacy else 0 for c in by_return[:5]])
    struct.pack_into('<3d3d6d', h, 131, *SCALE, *OFFSET, hi[0], lo[0], hi[1], lo[1], hi[2], lo[2])
    if minor >= 4:
        struct.pack_into('<QQIQ15Q', h, 227, 0, 0, 0, n, *by_return)
    with open(path, 'wb') as f:
        f.write(bytes(h) + vlrs + body)
    json.dump(dict(count=n, scale=SCALE, offset=OFFSET, min=lo, max=hi, world=world,
                   rgb=[p['rgb'] for p in pts] if fmt in (2, 3, 7, 8) else None,
                   intensity=[p['intensity'] for p in pts], classification=[p['cls'] for p in pts],
                   return_number=[p['ret'] for p in pts], gps_time=[p['gps'] for p in pts] if fmt in (1, 3, 6, 7, 8) else None,
                   height=[p['height'] for p in pts] if extra else None), sys.stdout)


if __name__ == '__main__':
    main()
