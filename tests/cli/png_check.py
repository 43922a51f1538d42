# png_check.py FILE EXPR: decodes an 8-bit RGBA PNG (any row filter) and evaluates the Python
# expression EXPR with w, h, px(x, y) -> (r, g, b, a) and fg = the fraction of pixels whose colour
# is not the white background. Exit status 1 with a message when EXPR is false. Used by the CLI
# tests through check() in common.sh; standard library only.
import struct, sys, zlib

data = open(sys.argv[1], 'rb').read()
assert data[:8] == b'\x89PNG\r\n\x1a\n', 'not a PNG'
pos, idat = 8, b''
while pos < len(data):
    n, t = struct.unpack('>I4s', data[pos:pos + 8])
    body = data[pos + 8:pos + 8 + n]
    if t == b'IHDR':
        w, h, depth, ctype = struct.unpack('>IIBB', body[:10])
        assert depth == 8 and ctype == 6, 'expected 8-bit RGBA'
    elif t == b'IDAT':
        idat += body
    pos += 12 + n
raw, stride, rows, prev = zlib.decompress(idat), 4 * w, [], bytearray(4 * w)
for y in range(h):
    f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
    for i in range(stride):
        a = line[i - 4] if i >= 4 else 0
        b = prev[i]
        c = prev[i - 4] if i >= 4 else 0
        if f == 1: line[i] = (line[i] + a) & 255
        elif f == 2: line[i] = (line[i] + b) & 255
        elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
        elif f == 4:
            p = a + b - c; pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
            line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
    rows.append(line); prev = line
px = lambda x, y: tuple(rows[y][4 * x:4 * x + 4])
fg = sum(px(x, y)[:3] != (255, 255, 255) for x in range(w) for y in range(h)) / (w * h) if 'fg' in sys.argv[2] else 0.0
if not eval(sys.argv[2]):
    sys.exit('assertion failed: %s (w=%d h=%d fg=%.4f, centre %s, corner %s)'
             % (sys.argv[2], w, h, fg, px(w // 2, h // 2), px(0, 0)))
