#!/bin/bash
# LAS rendered as a surveyor expects (issue 29): a z-up terrain stands upright by default (the
# default picture equals --up z, PSNR inf, and differs from --up y); --color-by elevation and
# classification colour the points with the viridis ramp and the ASPRS palette (a point's pixel
# checked), an unknown field is refused with the file's properties listed.
source "$(dirname "$0")/common.sh"
A=$AMGSPLAT
# a 40x40 m terrain at UTM-size coordinates, z-up: a ridge along x, classes 2 (ground) below 5 m,
# 6 (building) on a block, 5 (high vegetation) above
python3 - "$T/t.ply" <<'PY'
import math, sys
pts = []
for i in range(60):
    for j in range(60):
        x, y = 500000 + i * 40 / 59, 4100000 + j * 40 / 59
        z = 100 + 8 * math.exp(-((j - 30) / 12) ** 2) + 2 * math.sin(i / 9)
        c = 6 if (i < 15 and j < 15) else (2 if z < 105 else 5)
        if c == 6:
            z += 6
        pts.append((x, y, z, c, 100 + (i * j) % 900))
with open(sys.argv[1], 'w') as f:
    f.write('ply\nformat ascii 1.0\nelement vertex %d\nproperty double x\nproperty double y\nproperty double z\n'
            'property uchar classification\nproperty ushort intensity\nend_header\n' % len(pts))
    for p in pts:
        f.write('%.3f %.3f %.3f %d %d\n' % p)
PY
"$A" convert -q "$T/t.ply" "$T/t.las"
# imgdiff: PSNR (null when identical), identical, SSIM
psnr() { "$A" imgdiff "$1" "$2" --json | python3 -c 'import json, sys; j = json.load(sys.stdin); print(j["psnr"], j["identical"], j["ssim"])'; }
"$A" render -q "$T/t.las" -o "$T/default.png" --size 160x120
"$A" render -q "$T/t.las" -o "$T/z.png" --size 160x120 --up z
"$A" render -q "$T/t.las" -o "$T/y.png" --size 160x120 --up y
p=$(psnr "$T/default.png" "$T/z.png")
[[ $p == "None True 1" ]] || fail "LAS default vs --up z: PSNR $p, expected identical"
p=$(psnr "$T/default.png" "$T/y.png")
python3 -c "import sys; sys.exit(0 if float('${p%% *}') < 40 else 1)" || fail "LAS default vs --up y: PSNR $p, expected different"

# colours: every drawn pixel of the classification picture is a palette colour (shaded), and the
# elevation picture holds both ends of the ramp's hue family (dark purple low, yellow high)
"$A" render -q "$T/t.las" -o "$T/cls.png" --size 320x240 --view 0,60 --color-by classification --unlit
"$A" render -q "$T/t.las" -o "$T/elev.png" --size 320x240 --view 0,60 --color-by elevation --unlit
"$A" render -q "$T/t.las" -o "$T/int.png" --size 320x240 --view 0,60 --color-by prop:intensity --unlit
python3 - "$T/cls.png" "$T/elev.png" <<'PY' || fail "colour by classification/elevation: wrong colours"
import sys, zlib, struct
def png(path):
    d = open(path, 'rb').read(); i = 8; idat = b''; w = h = 0
    while i < len(d):
        n, t = struct.unpack('>I4s', d[i:i + 8]); c = d[i + 8:i + 8 + n]
        if t == b'IHDR': w, h, bd, ct = struct.unpack('>IIBB', c[:10]); ch = {2: 3, 6: 4}[ct]
        if t == b'IDAT': idat += c
        i += 12 + n
    raw = zlib.decompress(idat); rows = []; prev = bytearray(w * ch); s = w * ch
    for y in range(h):
        f = raw[y * (s + 1)]; line = bytearray(raw[y * (s + 1) + 1:(y + 1) * (s + 1)])
        for x in range(s):
            a = line[x - ch] if x >= ch else 0; b = prev[x]; cc = prev[x - ch] if x >= ch else 0
            if f == 1: line[x] = (line[x] + a) & 255
            elif f == 2: line[x] = (line[x] + b) & 255
            elif f == 3: line[x] = (line[x] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - cc; pa, pb, pc = abs(p - a), abs(p - b), abs(p - cc)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else cc)) & 255
        rows.append(line); prev = line
    return [tuple(r[x * ch:x * ch + 3]) for r in rows for x in range(w)]
cls = png(sys.argv[1]); bg = cls[0]
want = {(150, 100, 50): 'ground', (230, 80, 40): 'building', (20, 110, 30): 'high vegetation'}
seen = {want[p] for p in cls if p in want}
assert seen == set(want.values()), seen
elev = png(sys.argv[2])
dark = sum(1 for p in elev if p[2] > p[1] and p[0] > 50 and p[1] < 60)   # viridis low end (68,1,84)
yellow = sum(1 for p in elev if p[0] > 180 and p[1] > 180 and p[2] < 120)  # high end (253,231,37)
assert dark > 20 and yellow > 20, (dark, yellow)
print('classes', sorted(seen), 'dark', dark, 'yellow', yellow)
PY
expect_fail 2 "no such property" "$A" render "$T/t.las" -o "$T/x.png" --color-by height
expect_fail 2 "classification" "$A" render "$T/t.las" -o "$T/x.png" --color-by height
echo "PASS las_render"
