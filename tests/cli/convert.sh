#!/bin/bash
# amgsplat convert: PLY <-> text round trips keep the points, encodings are as
# asked, bad input and bad usage give the documented exit codes and messages.
set -euo pipefail
: "${AMGSPLAT:?}" "${ASP_TEST_SRC:?}" "${ASP_TEST_TMP:?}"
T="$ASP_TEST_TMP/convert"
rm -rf "$T" && mkdir -p "$T"
fail() { echo "FAIL: $*" >&2; exit 1; }

# a small ascii PLY with normals, colours, a face and an extra property
cat > "$T/in.ply" <<'PLY'
ply
format ascii 1.0
comment hello
element vertex 4
property float x
property float y
property float z
property float nx
property float ny
property float nz
property uchar red
property uchar green
property uchar blue
property short quality
element face 1
property list uchar int vertex_indices
end_header
0 0 0 0 0 1 255 0 0 -5
1 0 0 0 0 1 0 255 0 6
1 1 0 0 0 1 0 0 255 7
0 1 0.5 0 0 1 10 20 30 8
4 0 1 2 3
PLY

# PLY ascii -> binary LE (default) -> big endian -> ascii: the ascii text must come back identical
"$AMGSPLAT" convert -q "$T/in.ply" "$T/le.ply"
head -c 40 "$T/le.ply" | grep "format binary_little_endian" >/dev/null || fail "default is not binary little endian"
"$AMGSPLAT" convert --big-endian -q "$T/le.ply" "$T/be.ply"
head -c 40 "$T/be.ply" | grep "format binary_big_endian" >/dev/null || fail "--big-endian ignored"
"$AMGSPLAT" convert --ascii -q "$T/be.ply" "$T/back.ply"
"$AMGSPLAT" convert --ascii -q "$T/in.ply" "$T/direct.ply"
cmp -s "$T/back.ply" "$T/direct.ply" || fail "binary round trip changed the data"
grep -q "^comment hello$" "$T/back.ply" || fail "comment lost"
grep -q "^property short quality$" "$T/back.ply" || fail "extra property lost"
grep -q "^element face 2$" "$T/back.ply" || fail "quad not triangulated into 2 faces"
grep -q "^1 1 0 0 0 1 0 0 255 7$" "$T/back.ply" || fail "vertex values changed"

# summary line and JSON
out=$("$AMGSPLAT" convert "$T/in.ply" "$T/pts.xyz" 2>"$T/err.txt")
[[ "$out" == *"4 points (normals, colors), 2 faces, 1 extra properties"* ]] || fail "summary: $out"
grep -q "dropped faces, comments, extra properties" "$T/err.txt" || fail "no note about dropped data: $(cat "$T/err.txt")"
json=$("$AMGSPLAT" convert --json "$T/pts.xyz" "$T/from_xyz.ply")
[[ "$json" == *'"points": 4'* && "$json" == *'"attributes": ["normals", "colors"]'* ]] || fail "json: $json"
[ "$(wc -l < "$T/pts.xyz")" -eq 4 ] || fail "xyz should have 4 lines"
grep -q "^1 1 0 0 0 1 0 0 255$" "$T/pts.xyz" || fail "xyz line wrong: $(cat "$T/pts.xyz")"
"$AMGSPLAT" convert -q "$T/pts.xyz" "$T/count.pts"
[ "$(head -1 "$T/count.pts")" = "4" ] || fail ".pts has no count line"
[ -z "$("$AMGSPLAT" convert -q "$T/in.ply" "$T/q.ply")" ] || fail "--quiet printed"

# errors: exit 1 with the library's message, exit 2 for usage; no output file is left behind
set +e
"$AMGSPLAT" convert "$ASP_TEST_SRC/data/bad/nan_ascii.ply" "$T/nan.ply" 2>"$T/err.txt"; rc=$?
set -e
[ $rc -eq 1 ] || fail "NaN input: exit $rc"
grep -q "line 9: coordinate y is NaN" "$T/err.txt" || fail "NaN message: $(cat "$T/err.txt")"
[ ! -e "$T/nan.ply" ] || fail "output written for bad input"
set +e
"$AMGSPLAT" convert "$T/missing.ply" "$T/x.ply" 2>"$T/err.txt"; rc1=$?
"$AMGSPLAT" convert "$T/in.ply" "$T/x.abc" 2>"$T/err2.txt"; rc2=$?
"$AMGSPLAT" convert "$T/in.ply" 2>/dev/null; rc3=$?
"$AMGSPLAT" convert --ascii --big-endian "$T/in.ply" "$T/x.ply" 2>/dev/null; rc4=$?
"$AMGSPLAT" convert --ascii "$T/in.ply" "$T/x.xyz" 2>/dev/null; rc5=$?
"$AMGSPLAT" convert --bogus "$T/in.ply" "$T/x.ply" 2>/dev/null; rc6=$?
set -e
[ $rc1 -eq 1 ] && grep -q "cannot open '.*missing.ply': No such file" "$T/err.txt" || fail "missing input: $rc1"
[ $rc2 -eq 1 ] && grep -q "unknown point format '.abc'" "$T/err2.txt" || fail "unknown extension: $rc2"
[ $rc3 -eq 2 ] && [ $rc4 -eq 2 ] && [ $rc5 -eq 2 ] && [ $rc6 -eq 2 ] || fail "usage errors: $rc3 $rc4 $rc5 $rc6"
"$AMGSPLAT" convert -h | grep "usage: amgsplat convert" >/dev/null || fail "-h"

# --in-memory: the hierarchy with splat ellipses, in the in-memory layout (info shows no streamed
# layout), which render's splat renderer draws and export --tiles writes as Gaussian splats
"$AMGSPLAT" synth torus -o "$T/torus.ply" --points 20000 -q
"$AMGSPLAT" convert "$T/torus.ply" -o "$T/torus.hier" --in-memory --json >"$T/mem.json" || fail "convert --in-memory"
"$AMGSPLAT" info "$T/torus.hier" --json >"$T/mem_info.json"
python3 - "$T/mem.json" "$T/mem_info.json" <<'PY' || fail "--in-memory: $(cat "$T/mem.json" "$T/mem_info.json")"
import json, sys
c, i = (json.load(open(p)) for p in sys.argv[1:3])
assert c['encoding'] == 'hier' and c['points'] == 20000 and c['nodes'] > 1, c
assert i['kind'] == 'hier' and i['points'] == 20000 and i['nodes'] == c['nodes'] and i.get('layout') != 'streamed', i
PY
"$AMGSPLAT" render "$T/torus.hier" -o "$T/mem.png" --size 96x96 -q || fail "render of the in-memory .hier"
"$AMGSPLAT" export "$T/torus.hier" -o "$T/mem_tiles" --tiles --json >"$T/mem_tiles.json" || fail "tiles"
python3 -c "
import json, sys
j = json.load(open(sys.argv[1]))
assert j['refine'] == 'REPLACE' and j['gaussian_splats'] and j['points'] == 20000, j" "$T/mem_tiles.json" ||
  fail "tiles of the in-memory .hier: $(cat "$T/mem_tiles.json")"
rc=0; "$AMGSPLAT" convert "$T/torus.ply" -o "$T/x.ply" --in-memory 2>"$T/e1" || rc=$?
[[ $rc == 2 ]] && grep -q -- "--in-memory applies to .hier output" "$T/e1" || fail "--in-memory on a PLY: $rc $(cat "$T/e1")"
rc=0; "$AMGSPLAT" convert "$T/torus.ply" -o "$T/x.hier" --in-memory --node-points 100 2>"$T/e2" || rc=$?
[[ $rc == 2 && ! -e "$T/x.hier" ]] || fail "--in-memory --node-points: $rc $(cat "$T/e2")"
echo "convert: ok"
