# amgsplat imgdiff: identical images, a known PSNR, size mismatch, unreadable input; silhouettes of
# opaque images from the background (detected from the corners, or --background), of transparent ones
# from alpha: a disc and a square on white report their true IoU (issue 12), not 1.
source "$(dirname "$0")/common.sh"
# 16x16 RGBA PNGs written with python's zlib (no PIL needed)
python3 - "$T" <<'PY'
import struct, zlib, sys
def png(path, w, h, px):
    rows = b''
    for y in range(h):
        rows += b'\x00' + b''.join(bytes(px(x, y)) for x in range(w))
    def chunk(t, d): return struct.pack('>I', len(d)) + t + d + struct.pack('>I', zlib.crc32(t + d) & 0xffffffff)
    open(path, 'wb').write(b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', w, h, 8, 6, 0, 0, 0))
                            + chunk(b'IDAT', zlib.compress(rows)) + chunk(b'IEND', b''))
d = sys.argv[1]
png(d + '/a.png', 16, 16, lambda x, y: (x * 16, y * 16, 100, 255))
png(d + '/b.png', 16, 16, lambda x, y: (x * 16 + 5 if x < 8 else x * 16 - 5, y * 16, 100, 255))
png(d + '/c.png', 16, 12, lambda x, y: (0, 0, 0, 255))
# a shaded disc and a square on white (opaque), and the same with alpha 0 off the shapes
disc = lambda x, y: (x + 0.5 - 32) ** 2 + (y + 0.5 - 32) ** 2 <= 400
square = lambda x, y: x >= 30 and y >= 30
shade = lambda x, y: (40 + 2 * x, 30 + y, 90, 255)
for nm, f in (('disc', disc), ('square', square)):
    png(d + '/' + nm + '.png', 64, 64, lambda x, y, f=f: shade(x, y) if f(x, y) else (255, 255, 255, 255))
    png(d + '/' + nm + '_a.png', 64, 64, lambda x, y, f=f: shade(x, y) if f(x, y) else (255, 255, 255, 0))
cells = [(x, y) for y in range(64) for x in range(64)]
both = sum(1 for c in cells if disc(*c) and square(*c))
union = sum(1 for c in cells if disc(*c) or square(*c))
open(d + '/want', 'w').write('%.10f' % (both / union))
PY
"$AMGSPLAT" imgdiff "$T/a.png" "$T/a.png" | grep "psnr inf" >/dev/null || fail "identical images"
"$AMGSPLAT" imgdiff "$T/a.png" "$T/a.png" | grep "ssim 1.000000" >/dev/null || fail "ssim of identical images"
# one channel of three off by 5 everywhere: MSE = 25/3, PSNR = 10 log10(255^2 * 3 / 25) = 38.922 dB
"$AMGSPLAT" imgdiff --json "$T/a.png" "$T/b.png" >"$T/j"
python3 -c "import json,sys,math; d=json.load(open(sys.argv[1])); assert abs(d['psnr']-10*math.log10(255**2*3/25))<1e-3, d; assert d['iou']==1" "$T/j" \
  || fail "psnr of known difference: $(cat "$T/j")"
expect_fail 1 "images differ in size: 16x16 and 16x12" "$AMGSPLAT" imgdiff "$T/a.png" "$T/c.png"
expect_fail 1 "cannot open '$T/nope.png'" "$AMGSPLAT" imgdiff "$T/a.png" "$T/nope.png"
want=$(cat "$T/want")
# default: the white background is detected from the corners (3 of 4 for the square, which covers one)
"$AMGSPLAT" imgdiff --json "$T/disc.png" "$T/square.png" >"$T/j"
python3 -c "
import json, sys
d = json.load(open(sys.argv[1])); want = float(sys.argv[2]); s = d['silhouette']
assert abs(d['iou'] - want) < 1e-6 and want < 0.5, (d['iou'], want)
assert [x['source'] for x in s] == ['corners', 'corners'], s
assert s[0]['background'] == [255, 255, 255] and s[1]['background'] == [255, 255, 255], s
assert s[0]['corners_agreeing'] == 4 and s[1]['corners_agreeing'] == 3, s
assert s[1]['pixels'] == 34 * 34 and d['tolerance'] == 8, d
" "$T/j" "$want" || fail "disc and square on white: $(cat "$T/j")"
"$AMGSPLAT" imgdiff "$T/disc.png" "$T/square.png" | grep "silhouette B: corners 255,255,255 (3 of 4 corners)" >/dev/null \
  || fail "text output names the silhouette source"
# --background: the given colour; a wrong one makes every pixel silhouette (IoU 1)
"$AMGSPLAT" imgdiff --json --background 255,255,255 "$T/disc.png" "$T/square.png" >"$T/j"
python3 -c "
import json, sys
d = json.load(open(sys.argv[1])); assert abs(d['iou'] - float(sys.argv[2])) < 1e-6, d
assert [x['source'] for x in d['silhouette']] == ['background', 'background'], d
" "$T/j" "$want" || fail "--background 255,255,255: $(cat "$T/j")"
"$AMGSPLAT" imgdiff --json --background 0,0,0 "$T/disc.png" "$T/square.png" >"$T/j"
python3 -c "import json,sys; d=json.load(open(sys.argv[1])); assert d['iou'] == 1, d" "$T/j" \
  || fail "--background 0,0,0 on white images: $(cat "$T/j")"
# alpha: transparent images use it, whatever --background says
"$AMGSPLAT" imgdiff --json --background 0,0,0 "$T/disc_a.png" "$T/square_a.png" >"$T/j"
python3 -c "
import json, sys
d = json.load(open(sys.argv[1])); assert abs(d['iou'] - float(sys.argv[2])) < 1e-6, d
assert [x['source'] for x in d['silhouette']] == ['alpha', 'alpha'], d
" "$T/j" "$want" || fail "alpha silhouettes: $(cat "$T/j")"
expect_fail 2 "--background expects R,G,B" "$AMGSPLAT" imgdiff --background 1,2 "$T/a.png" "$T/a.png"
expect_fail 2 "--tolerance expects 0..255" "$AMGSPLAT" imgdiff --tolerance 300 "$T/a.png" "$T/a.png"
echo "imgdiff: ok"
