#!/bin/bash
# LAS in and out: a LAS 1.4 format 7 file built byte by byte from the specification (scale 0.001,
# UTM-size offsets) reads back every point within half a scale step with every field; the C writer's
# files (from LAS and from PLY) read back the same; @loaders.gl/las, an independent reader (its
# laz-rs loader, which reads LAS 1.0-1.4), agrees on counts, bounds and colours of the 1.4 format 7
# files, hand-built and written, and of 1.2 files of formats 2 and 3; LAZ and broken
# files give clear errors; info shows the LAS header.
source "$(dirname "$0")/common.sh"
: "${ASP_TEST_SRC:?}"
A=$AMGSPLAT
MAKE="python3 $ASP_TEST_SRC/cli/las_handmade.py"
WEB=$ASP_TEST_SRC/../web

# compare_ply EXPECTED.json FILE.ply WHAT: every point of the ascii PLY (from our reader) against the
# generator's values: coordinates within half a scale step, colours = the 16-bit values >> 8, fields equal
compare_ply() {
  python3 - "$1" "$2" "$3" <<'PY' || fail "$3"
import json, sys
exp = json.load(open(sys.argv[1])); what = sys.argv[3]
lines = open(sys.argv[2]).read().split('\n')
end = lines.index('end_header')
props = [l.split()[-1] for l in lines[:end] if l.startswith('property')]
rows = [l.split() for l in lines[end + 1:end + 1 + exp['count']]]
assert len(rows) == exp['count'], (what, len(rows))
col = {p: i for i, p in enumerate(props)}
worst = 0.0
for i, r in enumerate(rows):
    for k, a in enumerate('xyz'):
        worst = max(worst, abs(float(r[col[a]]) - exp['world'][i][k]))
    if exp['rgb']:
        got = [int(r[col[c]]) for c in ('red', 'green', 'blue')]
        want = [v >> 8 for v in exp['rgb'][i]] if max(max(t) for t in exp['rgb']) > 255 else exp['rgb'][i]
        assert got == want, (what, i, got, want)
        assert [int(r[col[c]]) for c in ('red16', 'green16', 'blue16')] == exp['rgb'][i], (what, i)
    for f in ('intensity', 'classification', 'return_number'):
        assert int(r[col[f]]) == exp[f][i], (what, f, i, r[col[f]], exp[f][i])
    if exp['gps_time']:
        assert float(r[col['gps_time']]) == exp['gps_time'][i], (what, i)
    if exp['height']:
        assert float(r[col['height']]) == exp['height'][i], (what, i)
half = exp['scale'][0] / 2
print(f"{what}: {len(rows)} points, worst coordinate error {worst:.3g} (half a scale step {half:g})")
assert worst <= half, (what, worst)
PY
}

# 1. hand-built LAS 1.4 format 7 with an Extra Bytes float: our reader, every point and field
$MAKE "$T/h7.las" 4 7 2000 --extra > "$T/h7.json"
"$A" convert -q --ascii "$T/h7.las" "$T/h7.ply"
compare_ply "$T/h7.json" "$T/h7.ply" "hand-built 1.4 format 7"
"$A" info "$T/h7.las" > "$T/info.txt"
grep -F "version 1.4, point format 7, 40-byte records, 2000 points" "$T/info.txt" >/dev/null || fail "info: $(cat "$T/info.txt")"
grep -F "las offset  500000 5000000 300" "$T/info.txt" >/dev/null || fail "info offset: $(cat "$T/info.txt")"
"$A" info --json "$T/h7.las" | python3 -c '
import json, sys
d = json.load(sys.stdin)
l = d["las"]
assert d["points"] == 2000 and l["version"] == "1.4" and l["point_format"] == 7, d
assert l["scale"] == [0.001] * 3 and l["offset"] == [500000, 5000000, 300], l
assert l["points_by_return"][:3] == [667, 667, 666], l["points_by_return"]
assert d["colors"] and {"name": "height", "type": "float"} in d["properties"], d["properties"]
' || fail "info --json on LAS"

# 2. the C writer, LAS -> LAS: the same point records, scale, offset and bounds
"$A" convert -q "$T/h7.las" "$T/w7.las"
python3 - "$T/h7.las" "$T/w7.las" <<'PY' || fail "LAS -> LAS changed the records"
import struct, sys
a, b = open(sys.argv[1], 'rb').read(), open(sys.argv[2], 'rb').read()
pa, pb = struct.unpack_from('<I', a, 96)[0], struct.unpack_from('<I', b, 96)[0]
assert a[pa:] == b[pb:], "point records differ"
assert a[104:107] == b[104:107] and a[131:227] == b[131:227] and a[227:375] == b[227:375], "header differs"
PY
"$A" convert -q --ascii "$T/w7.las" "$T/w7.ply"
compare_ply "$T/h7.json" "$T/w7.ply" "C writer 1.4 format 7 (from LAS)"

# 3. the C writer from a PLY with UTM coordinates (no LAS source): format 7, scale 0.001, offsets
#    from the data; every point back within half a step of the PLY's double coordinates
python3 - "$T/utm.ply" <<'PY'
import math, sys
n = 1500
with open(sys.argv[1], 'w') as f:
    f.write('ply\nformat ascii 1.0\nelement vertex %d\nproperty double x\nproperty double y\nproperty double z\n'
            'property uchar red\nproperty uchar green\nproperty uchar blue\nproperty ushort intensity\nend_header\n' % n)
    for i in range(n):
        f.write('%.3f %.3f %.3f %d %d %d %d\n' % (512345.678 + 0.731 * i, 5412345.125 + 100 * math.sin(i),
                                                 312.5 + (i % 50) * 0.011, i % 256, (3 * i) % 256, 255 - i % 256, i))
PY
"$A" convert --json "$T/utm.ply" "$T/utm.las" > "$T/conv.json"
python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); assert d["encoding"]=="las" and d["points"]==1500, d' "$T/conv.json" \
  || fail "convert --json: $(cat "$T/conv.json")"
"$A" convert -q --ascii "$T/utm.las" "$T/utm_back.ply"
python3 - "$T/utm.ply" "$T/utm_back.ply" "$T/utm.las" <<'PY' || fail "PLY -> LAS -> PLY"
import struct, sys
def rows(p):
    t = open(p).read().split('\n'); e = t.index('end_header')
    return [l.split() for l in t[e + 1:] if l]
a, b = rows(sys.argv[1]), rows(sys.argv[2])
assert len(a) == len(b) == 1500
las = open(sys.argv[3], 'rb').read()
assert las[24:26] == b'\x01\x04' and las[104] == 7, "expected LAS 1.4 format 7"
scale = struct.unpack_from('<3d', las, 131); offset = struct.unpack_from('<3d', las, 155)
assert scale == (0.001,) * 3, scale
worst = max(abs(float(x[k]) - float(y[k])) for x, y in zip(a, b) for k in range(3))
assert worst <= 0.0005, worst
assert all(x[3:6] == y[3:6] for x, y in zip(a, b)), "colours"
print(f"PLY -> LAS 1.4 format 7 -> PLY: offsets {offset}, worst coordinate error {worst:.3g}")
PY

# 4. the independent reader, @loaders.gl/las (laz-rs loader), against ours: h7 and w7 (hand-built
# LAS 1.4 format 7 and the C writer's copy), utm (the C writer's 1.4 format 7 of a PLY), and 1.2 files
if [[ -d $WEB/node_modules/@loaders.gl/las ]] && command -v node >/dev/null; then
  $MAKE "$T/h3.las" 2 3 2000 > "$T/h3.json"                 # hand-built LAS 1.2 format 3
  "$A" convert -q --las-format 3 "$T/h7.las" "$T/w3.las"     # the C writer's 1.2 format 3 of the 1.4 file
  "$A" convert -q --las-format 3 "$T/utm.ply" "$T/u3.las"    # ... and of the PLY
  "$A" convert -q --las-format 2 --las-scale 0.01 "$T/utm.ply" "$T/u2.las"
  for f in h7 w7 utm h3 w3 u3 u2; do
    node "$WEB/test/las_check.mjs" "$T/$f.las" > "$T/$f.lg.json" || fail "loaders.gl cannot read $f.las: $(cat "$T/$f.lg.json")"
    "$A" info --json "$T/$f.las" > "$T/$f.info.json"
    "$A" convert -q --ascii "$T/$f.las" "$T/$f.ply"
    python3 - "$T/$f.lg.json" "$T/$f.info.json" "$T/$f.ply" "$f" <<'PY' || fail "loaders.gl and amgsplat disagree on $f.las"
import json, sys
lg, info, name = json.load(open(sys.argv[1])), json.load(open(sys.argv[2])), sys.argv[4]
t = open(sys.argv[3]).read().split('\n'); e = t.index('end_header')
props = [l.split()[-1] for l in t[:e] if l.startswith('property')]
rows = [l.split() for l in t[e + 1:] if l]
half = info['las']['scale'][0] / 2
assert lg['count'] == info['points'] == len(rows), (lg['count'], info['points'])
ours = [[float(r[k]) for r in rows] for k in range(3)]
worst = 0.0
for k in range(3):
    worst = max(worst, abs(min(ours[k]) - lg['min'][k]), abs(max(ours[k]) - lg['max'][k]),
                abs(info['bbox_min'][k] - lg['min'][k]), abs(info['bbox_max'][k] - lg['max'][k]),
                abs(float(rows[0][k]) - lg['first_position'][k]), abs(float(rows[-1][k]) - lg['last_position'][k]))
assert worst <= half, (name, worst, half)
ci = [props.index(c) for c in ('red', 'green', 'blue')]
first = [int(rows[0][i]) for i in ci] + [255]
last = [int(rows[-1][i]) for i in ci] + [255]
assert lg['first_color'] == first and lg['last_color'] == last, (name, lg['first_color'], first, lg['last_color'], last)
ii = props.index('intensity')
assert lg['intensity'] == [int(rows[0][ii]), int(rows[-1][ii])], (name, lg['intensity'])
print(f"{name}.las: loaders.gl and amgsplat agree: {lg['count']} points, bounds within {worst:.3g} "
      f"(half step {half:g}), colours {first} ... {last}")
PY
  done
else
  asp_skipped+=("web/node_modules (cd web && npm ci) for the @loaders.gl/las cross-check")
fi

# 5. LAZ and broken files: clear errors naming the file
python3 -c 'import sys; b=bytearray(open(sys.argv[1],"rb").read()); b[104]|=0x80; open(sys.argv[2],"wb").write(b)' "$T/h7.las" "$T/x.laz"
expect_fail 1 "cannot read '$T/x.laz': compressed LAS (LASzip) needs a decompressor this build does not have; decompress it first (e.g. \`laszip -i x.laz -o x.las\`)" \
  "$A" info "$T/x.laz"
cp "$T/x.laz" "$T/zbit.las"   # by the format byte's bit 7 whatever the name
expect_fail 1 "cannot read '$T/zbit.las': compressed LAS (LASzip)" "$A" convert "$T/zbit.las" "$T/z.ply"
head -c 64 /dev/zero > "$T/junk.laz"   # by the name when the bytes say nothing
expect_fail 1 "cannot read '$T/junk.laz': compressed LAS (LASzip)" "$A" info "$T/junk.laz"
cp "$T/h7.las" "$T/plain.laz"    # an uncompressed file named .laz is read: the bytes decide
"$A" info "$T/plain.laz" | grep -F "point format 7" >/dev/null || fail "plain.laz"
head -c 5000 "$T/h7.las" > "$T/cut.las"
expect_fail 1 "cannot read '$T/cut.las': the header declares 2000 points of 40 bytes from byte 621, but the file holds only 109 whole records" \
  "$A" info "$T/cut.las"
python3 -c 'import sys,struct; b=bytearray(open(sys.argv[1],"rb").read()); struct.pack_into("<d",b,139,0.0); open(sys.argv[2],"wb").write(b)' "$T/h7.las" "$T/scale0.las"
expect_fail 1 "cannot read '$T/scale0.las': Y scale factor 0 (expected a finite non-zero number)" "$A" info "$T/scale0.las"
expect_fail 2 "--las-format applies to .las output only" "$A" convert --las-format 7 "$T/h7.las" "$T/o.ply"
expect_fail 2 "--las-format 5: expected 0, 1, 2, 3, 6, 7 or 8" "$A" convert --las-format 5 "$T/h7.las" "$T/o.las"
expect_fail 1 "cannot write '$T/o.laz': compressed LAS (LASzip) needs a compressor" "$A" convert "$T/h7.las" "$T/o.laz"
[[ ! -e $T/o.laz && ! -e $T/o.las ]] || fail "a failed convert left an output"
echo "las: all checks passed"
