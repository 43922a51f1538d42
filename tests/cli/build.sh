#!/usr/bin/env bash
# amgsplat build: octahedron primitives (8 faces at the coarsest level), the
# Table 5.2 output in text and JSON, info on the .dps, several levels, budget,
# texture methods, merge and normal maps, and the error cases (exit 1 / 2).
source "$(dirname "$0")/common.sh"
A="$AMGSPLAT"

"$A" build -h | grep "usage: amgsplat build" >/dev/null || fail "help"
"$A" help | grep "^  build " >/dev/null || fail "build missing from the command list"
"$A" synth octahedron -o "$T/oct.ply" -q
"$A" decompose "$T/oct.ply" -o "$T/oct.amg" -q

# the level with 8 basis functions: 8 primitives, small error, an atlas PNG
"$A" build "$T/oct.amg" -o "$T/oct.dps" --primitives 8 --atlas "$T/oct.png" --json > "$T/oct.json"
[ -s "$T/oct.dps" ] && [ -s "$T/oct.png" ] || fail "no .dps or atlas written"
python3 - "$T/oct.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
assert d["points"] == 16000 and d["method"] == "affine", d
(lv,) = d["levels"]
assert lv["primitives"] == 8, lv
assert lv["normalised_error"] < 0.1 and lv["skipped"] == 0 and lv["degenerate"] == 0, lv
assert lv["texels"] > 8 * 0.866 / d["mean_radius"] ** 2, lv
assert lv["atlas"][0] >= 64 and lv["atlas"][1] >= 1
PY
head -c 8 "$T/oct.png" | od -c | grep "P   N   G" >/dev/null || fail "atlas is not a PNG"

# info reads the same table back from the file
"$A" info "$T/oct.dps" > "$T/info.txt"
grep -q "^level  name   primitives" "$T/info.txt" || fail "info header: $(cat "$T/info.txt")"
grep -Eq "^ +[0-9]+  L +8 " "$T/info.txt" || fail "info row: $(cat "$T/info.txt")"
"$A" info "$T/oct.dps" --json | python3 -c "
import json, sys
d = json.load(sys.stdin)
b = json.load(open('$T/oct.json'))
assert d['levels'][0]['primitives'] == 8 and d['levels'][0]['texels'] == b['levels'][0]['texels']
assert d['source'].endswith('oct.amg'), d['source']"

# several levels in one file (range syntax), text table with the Table 5.2 columns
"$A" build "$T/oct.amg" -o "$T/multi.dps" --level L-3..L > "$T/multi.txt"
grep -q "primitives    texels        error  normalised   cb (s)  dpc (s)" "$T/multi.txt" || fail "table header"
[ "$(grep -Ec '^ +[0-9]+  L' "$T/multi.txt")" = 4 ] || fail "expected 4 level rows: $(cat "$T/multi.txt")"
"$A" info "$T/multi.dps" --json | python3 -c "
import json, sys
d = json.load(sys.stdin)
names = [l['name'] for l in d['levels']]
assert names == ['L-3', 'L-2', 'L-1', 'L'], names
p = [l['primitives'] for l in d['levels']]
assert p == sorted(p, reverse=True), p"

# a .ply input is decomposed first; every texture method and option runs
"$A" build "$T/oct.ply" -o "$T/ply.dps" --level L -q
for m in "--method radial --shape constant" "--method radial --shape gaussian --width 2" \
         "--method radial --normalise ge1 --width 2" "--normals --merge" "--unweighted --project-radii --no-extend-color" \
         "--texel-size 3 --padding 1"; do
    # shellcheck disable=SC2086
    "$A" build "$T/oct.amg" -o "$T/m.dps" --level L $m --json > "$T/m.json" || fail "build $m"
    python3 -c "import json; d = json.load(open('$T/m.json')); assert 8 <= d['levels'][0]['primitives'] <= 9, d" \
        || fail "$m: $(cat "$T/m.json")"
done
"$A" info "$T/m.dps" > /dev/null
# the texture cap bites: a warning, still a valid file
"$A" build "$T/oct.amg" -o "$T/cap.dps" --level L --texel-size 0.1 --max-texture 32 2> "$T/cap.err" > /dev/null
grep -q "warning: level L: .* reached --max-texture 32" "$T/cap.err" || fail "cap warning: $(cat "$T/cap.err")"

# damaged files: exit 1 with the reason
head -c 3000 "$T/oct.dps" > "$T/cut.dps"
expect_exit 1 "$A" info "$T/cut.dps"
grep -q "truncated" "$T/err" || fail "truncated: $(cat "$T/err")"
cp "$T/oct.dps" "$T/flip.dps"
printf '\x7f' | dd of="$T/flip.dps" bs=1 seek=2000 conv=notrunc status=none
expect_exit 1 "$A" info "$T/flip.dps"
grep -q "checksum" "$T/err" || fail "corrupted: $(cat "$T/err")"
# the first bytes decide: a PLY named .dps is described as the points it holds
cp "$T/oct.ply" "$T/notdps.dps"
"$A" info "$T/notdps.dps" | grep "^points *16000$" >/dev/null || fail "a PLY named .dps"
# bytes no format claims, under a .dps name, are no .dps
head -c 300 /dev/zero | tr '\0' 'x' > "$T/junk.dps"
expect_exit 1 "$A" info "$T/junk.dps"
grep -q "not a .dps file" "$T/err" || fail "foreign: $(cat "$T/err")"

# bad input: exit 1, no output file
expect_exit 1 "$A" build "$T/missing.amg" -o "$T/x.dps"
expect_exit 1 "$A" build "$T/oct.amg" -o "$T/x.dps" --level L-99
grep -q "L-99" "$T/err" || fail "bad level: $(cat "$T/err")"
expect_exit 1 "$A" build "$T/oct.amg" -o "$T/x.dps" --level L --texel-size 1e-3 --max-texture 8192
grep -q "do not fit" "$T/err" || fail "atlas too large: $(cat "$T/err")"
[ ! -e "$T/x.dps" ] || fail "output written on failure"
# a directory or a FIFO named as input: a clear error at once, never a hang on the FIFO
mkdir "$T/dir.amg" && mkfifo "$T/fifo.amg"
expect_fail 1 "'$T/dir.amg': is a directory, expected a file" "$A" build "$T/dir.amg" -o "$T/x.dps"
expect_fail 1 "'$T/fifo.amg': not a regular file" timeout 20 "$A" build "$T/fifo.amg" -o "$T/x.dps"
mkdir "$T/dir.dps"
expect_fail 1 "'$T/dir.dps': is a directory, expected a file" "$A" info "$T/dir.dps"

# usage errors: exit 2
expect_exit 2 "$A" build
expect_exit 2 "$A" build "$T/oct.amg"
expect_exit 2 "$A" build "$T/oct.amg" -o "$T/x.dps" --method nope
grep -q "unknown texture method 'nope'" "$T/err" || fail "method: $(cat "$T/err")"
expect_exit 2 "$A" build "$T/oct.amg" -o "$T/x.dps" --level L --primitives 4
expect_exit 2 "$A" build "$T/oct.amg" -o "$T/x.dps" --texel-size -1
# upper-case .AMG input and .DPS output (the recogniser, not an extension matcher)
cp "$T/oct.amg" "$T/OCT.AMG"
"$A" build "$T/OCT.AMG" -o "$T/OCT.DPS" --level L -q || fail "build OCT.AMG"
"$A" info "$T/OCT.DPS" --json | python3 -c "import json,sys; d=json.load(sys.stdin); assert d['levels'][0]['primitives']==8, d" \
  || fail "info OCT.DPS"
echo "build: ok"
