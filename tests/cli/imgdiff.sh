# amgsplat imgdiff: identical images, a known PSNR, size mismatch, unreadable input.
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
PY
"$AMGSPLAT" imgdiff "$T/a.png" "$T/a.png" | grep "psnr inf" >/dev/null || fail "identical images"
"$AMGSPLAT" imgdiff "$T/a.png" "$T/a.png" | grep "ssim 1.000000" >/dev/null || fail "ssim of identical images"
# one channel of three off by 5 everywhere: MSE = 25/3, PSNR = 10 log10(255^2 * 3 / 25) = 38.922 dB
"$AMGSPLAT" imgdiff --json "$T/a.png" "$T/b.png" >"$T/j"
python3 -c "import json,sys,math; d=json.load(open(sys.argv[1])); assert abs(d['psnr']-10*math.log10(255**2*3/25))<1e-3, d; assert d['iou']==1" "$T/j" \
  || fail "psnr of known difference: $(cat "$T/j")"
expect_fail 1 "images differ in size: 16x16 and 16x12" "$AMGSPLAT" imgdiff "$T/a.png" "$T/c.png"
expect_fail 1 "cannot open '$T/nope.png'" "$AMGSPLAT" imgdiff "$T/a.png" "$T/nope.png"
echo "imgdiff: ok"
