# The one colour grammar of --background (cli_parse_colour, issue 26): render, view and imgdiff
# accept every spelling any of them accepted before (R,G,B; render's R,G,B,A; imgdiff's fractions)
# and #RRGGBB[AA]; out-of-range channels, trailing junk and malformed hex are refused alike.
source "$(dirname "$0")/common.sh"
# a 16x16 opaque mid-grey PNG (SSIM needs 11x11): imgdiff prints the background it parsed in its silhouette JSON
python3 - "$T" <<'PY'
import struct, zlib, sys
def chunk(t, d): return struct.pack('>I', len(d)) + t + d + struct.pack('>I', zlib.crc32(t + d) & 0xffffffff)
rows = b''.join(b'\x00' + bytes((128, 128, 128, 255)) * 16 for _ in range(16))
open(sys.argv[1] + '/g.png', 'wb').write(b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', 16, 16, 8, 6, 0, 0, 0))
                                         + chunk(b'IDAT', zlib.compress(rows)) + chunk(b'IEND', b''))
PY
# parsed SPELLING R G B: imgdiff read SPELLING as R,G,B
parsed() {
  local s=$1; shift
  "$AMGSPLAT" imgdiff --json --background "$s" "$T/g.png" "$T/g.png" >"$T/j" 2>"$T/e" \
    || fail "imgdiff --background '$s' refused: $(cat "$T/e")"
  python3 -c "import json,sys; b=json.load(open(sys.argv[1]))['silhouette'][0]['background']; \
assert b == [int(x) for x in sys.argv[2:]], b" "$T/j" "$@" || fail "--background '$s': $(cat "$T/j"), expected $*"
}
parsed 10,20,30 10 20 30
parsed "0, 128, 255" 0 128 255     # spaces after commas (strtod skips them)
parsed 255.0,2.55e2,0 255 255 0    # any number spelling that is a level
parsed 127.4,127.5,0.49 127 128 0  # imgdiff took fractions: rounded to the nearest level
parsed 1,2,3, 1 2 3                # the list parser's trailing comma
parsed "#0a141E" 10 20 30          # hex, either case
parsed "#FFffFF" 255 255 255
# refusals: every command the same message
for bad in 1,2 1,2,3,4,5 256,0,0 -1,0,0 1,2,3x x,1,2 1,,2,3 nan,0,0 inf,0,0 "1,2,3 " "" \
           "#12345" "#1234567" "#12345g" "#ffffff " "# ffffff" "#" ffffff "#fff"; do
  expect_fail 2 "--background expects R,G,B with channels in 0..255, or #RRGGBB, got '$bad'" \
    "$AMGSPLAT" imgdiff --background "$bad" "$T/g.png" "$T/g.png"
  expect_fail 2 "--background expects R,G,B[,A] with channels in 0..255, or #RRGGBB[AA], got '$bad'" \
    "$AMGSPLAT" render "$T/g.png" -o "$T/x.png" --background "$bad"
done
# an alpha: render's images have one; imgdiff's opaque images and view's window do not
expect_fail 2 "--background expects R,G,B with channels in 0..255, or #RRGGBB, got '1,2,3,4'" \
  "$AMGSPLAT" imgdiff --background 1,2,3,4 "$T/g.png" "$T/g.png"
expect_fail 2 "--background expects R,G,B with channels in 0..255, or #RRGGBB, got '#01020304'" \
  "$AMGSPLAT" imgdiff --background "#01020304" "$T/g.png" "$T/g.png"
expect_fail 2 "--background expects R,G,B with channels in 0..255, or #RRGGBB, got '1,2,3,4'" \
  "$AMGSPLAT" view "$T/g.png" --background 1,2,3,4
expect_fail 2 "--background expects R,G,B with channels in 0..255, or #RRGGBB, got '1,2,300'" \
  "$AMGSPLAT" view "$T/g.png" --background 1,2,300
# render: the pixels carry the parsed colour, alpha included, in every spelling
"$AMGSPLAT" synth sphere -n 500 -o "$T/s.ply" -q
# (a translucent background is blended in linear light: its colour comes back within a few levels)
near='px(0, 0)[3] == 40 and all(abs(a - b) <= 4 for a, b in zip(px(0, 0)[:3], (10, 20, 30)))'
"$AMGSPLAT" render "$T/s.ply" -o "$T/hex.png" --size 16x16 --background "#0A141E28" -q
check "$T/hex.png" "$near"
"$AMGSPLAT" render "$T/s.ply" -o "$T/dec.png" --size 16x16 --background 10,20,30.4,40 -q
check "$T/dec.png" "$near"
cmp -s "$T/hex.png" "$T/dec.png" || fail "#0A141E28 and 10,20,30.4,40 render differently"
"$AMGSPLAT" render "$T/s.ply" -o "$T/rgb.png" --size 16x16 --background "#0a141e" -q
check "$T/rgb.png" "px(0, 0) == (10, 20, 30, 255)"
echo "background: ok"
