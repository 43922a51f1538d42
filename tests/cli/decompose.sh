#!/usr/bin/env bash
# amgsplat decompose: .amg output, --stats/--json, colour export, re-reading
# an .amg, and the error cases (exit 1 for bad input, 2 for usage).
source "$(dirname "$0")/common.sh"
A="$AMGSPLAT"

"$A" decompose -h | grep "usage: amgsplat decompose" >/dev/null || fail "help"
"$A" synth octahedron -o "$T/oct.ply" -q

# decomposition + stats as JSON: 8 unknowns on some level, partition of unity on all
"$A" decompose "$T/oct.ply" -o "$T/oct.amg" --stats --json > "$T/oct.json"
[ -s "$T/oct.amg" ] || fail "no .amg written"
python3 - "$T/oct.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
st = d["level_stats"]
assert d["points"] == 16000, d["points"]
assert len(st) == d["levels"] >= 6, len(st)
# the crease test keeps the faces apart: the coarsest level is the 8 faces
assert st[0]["unknowns"] == 16000 and st[-1]["unknowns"] == 8, [s["unknowns"] for s in st]
for a, b in zip(st, st[1:]):
    assert b["unknowns"] < a["unknowns"]
    # about 2 per level while there is room; the last steps stop at the faces
    assert b["unknowns"] <= 16 or 1.5 <= a["unknowns"] / b["unknowns"] <= 4.5, (a["unknowns"], b["unknowns"])
for s in st:
    assert s["max_pou_error"] < 1e-6, s
    assert s["domains"] <= s["unknowns"] and s["mean_domains_per_point"] >= 1
assert st[-1]["name"] == "L-0"
assert set(d["seconds"]) == {"neighbours", "classifier", "fans", "assembly", "amg"}
PY

# the start with glibc's huge-page tunable (src/cli/huge_pages.c, where THP is in madvise mode) keeps
# the arguments and the result: the same file, byte for byte, as with it turned off
"$A" decompose "$T/oct.ply" -o "$T/oct_nohp.amg" -q
ASP_HUGE_PAGES=0 "$A" decompose "$T/oct.ply" -o "$T/oct_hp0.amg" -q
cmp -s "$T/oct_nohp.amg" "$T/oct_hp0.amg" || fail "decompose with and without the huge-page start differ"
cmp -s "$T/oct.amg" "$T/oct_hp0.amg" || fail "decompose with --stats and without differ"

# info on the .amg: the same level sizes as decompose reported, the points and attributes it keeps
"$A" info "$T/oct.amg" --json > "$T/info.json"
"$A" info "$T/oct.amg" > "$T/info.txt"
python3 - "$T/oct.json" "$T/info.json" "$T/info.txt" <<'PY'
import json, sys
d, i = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
txt = open(sys.argv[3]).read().splitlines()
assert i["points"] == 16000 and i["normals"] == "input" and i["colors"] and i["labels"], i
assert [l["unknowns"] for l in i["levels"]] == [s["unknowns"] for s in d["level_stats"]], i["levels"]
assert i["levels"][-1]["name"] == "L" and i["levels"][-2]["name"] == "L-1", i["levels"][-2:]
assert txt[1].split() == ["points", "16000"] and txt[-1].split()[:3] == [str(len(i["levels"]) - 1), "L", "8"], txt
PY

# text stats from the saved file, with the thesis threshold
"$A" decompose "$T/oct.amg" --stats --tau 0.01 > "$T/stats.txt"
grep -q "^level  name" "$T/stats.txt" || fail "stats header"
grep -Eq "^ +[0-9]+  L +[0-9]+" "$T/stats.txt" || fail "coarsest level L missing"

# colour export: domains of L-1 and the classifier, as PLY with colours
"$A" decompose "$T/oct.amg" --export-colors domains --level L-1 --colors-out "$T/dom.ply" -q
"$A" decompose "$T/oct.amg" --export-colors classifier --colors-out "$T/cls.ply" -q
head -c 400 "$T/dom.ply" | grep "property uchar red" >/dev/null || fail "no colours in export"
# the .amg keeps the whole point set: the synth's radii and face labels come back out of it
head -c 400 "$T/dom.ply" | grep "property float radius" >/dev/null || fail "radii lost in the .amg"
head -c 400 "$T/dom.ply" | grep "property uint label" >/dev/null || fail "labels lost in the .amg"
"$A" info "$T/dom.ply" > /dev/null

# options reach the library: a coarser strength threshold changes the hierarchy
"$A" decompose "$T/oct.ply" -o "$T/oct2.amg" --strong 0.25 --coarsen falgout --classifier moment --k 16 --json > "$T/o2.json"
python3 -c "import json,sys; a=json.load(open('$T/oct.json')); b=json.load(open('$T/o2.json')); assert b['k_min']==16 and a['level_sizes']!=b['level_sizes']"

# without the crease test the coarsest levels merge faces
"$A" decompose "$T/oct.ply" -o "$T/oct3.amg" --crease-cut=-1 --json > "$T/o3.json"
python3 -c "import json; d=json.load(open('$T/o3.json')); assert d['level_sizes'][-1] < 8, d['level_sizes']"
expect_exit 1 "$A" decompose "$T/oct.ply" -o "$T/x.amg" --crease-cut 2
grep -q "crease" "$T/err" || fail "bad crease cut: $(cat "$T/err")"

# degenerate inputs: clear messages, exit 1, no output file
printf 'ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n1 0 0\n' > "$T/two.ply"
expect_exit 1 "$A" decompose "$T/two.ply" -o "$T/two.amg"
grep -q "at least 3" "$T/err" || fail "two points: $(cat "$T/err")"
[ ! -e "$T/two.amg" ] || fail "output written on failure"
python3 -c "
print('ply\nformat ascii 1.0\nelement vertex 200\nproperty float x\nproperty float y\nproperty float z\nend_header')
for i in range(200): print(i * 0.1, i * 0.2, 0)" > "$T/line.ply"
expect_exit 1 "$A" decompose "$T/line.ply" -o "$T/line.amg"
grep -q "colinear" "$T/err" || fail "colinear: $(cat "$T/err")"
"$A" synth checker-plane --grid 40 -o "$T/plane.ply" -q
"$A" decompose "$T/plane.ply" -o "$T/plane.amg" -q

# damaged .amg files
head -c 1000 "$T/oct.amg" > "$T/cut.amg"
expect_exit 1 "$A" decompose "$T/cut.amg" --stats
grep -q "truncated" "$T/err" || fail "truncated: $(cat "$T/err")"
cp "$T/oct.amg" "$T/flip.amg"
printf '\x7f' | dd of="$T/flip.amg" bs=1 seek=5000 conv=notrunc status=none
expect_exit 1 "$A" decompose "$T/flip.amg" --stats
grep -q "checksum" "$T/err" || fail "corrupted: $(cat "$T/err")"
expect_exit 1 "$A" decompose "$T/oct.ply.missing.ply" -o "$T/x.amg"

# usage errors: exit 2
expect_exit 2 "$A" decompose
expect_exit 2 "$A" decompose "$T/oct.ply"
expect_exit 2 "$A" decompose "$T/oct.ply" -o "$T/x.amg" --coarsen nope
expect_exit 2 "$A" decompose "$T/oct.ply" -o "$T/x.amg" --classifier nope
expect_exit 2 "$A" decompose "$T/oct.amg" --export-colors domains
expect_exit 2 "$A" decompose "$T/oct.amg" --stats --tau 1.5
expect_exit 1 "$A" decompose "$T/oct.amg" --export-colors domains --level L-99 --colors-out "$T/x.ply"
grep -q "L-99" "$T/err" || fail "bad level: $(cat "$T/err")"
expect_exit 1 "$A" decompose "$T/oct.ply" -o "$T/x.amg" --strong 1.5
# upper-case names: the recogniser reads O.AMG as an .amg (by its magic), BUNNY.PLY as points
cp "$T/oct.amg" "$T/O.AMG"
"$A" decompose "$T/O.AMG" --stats --json > "$T/upper.json" || fail "decompose O.AMG"
python3 -c "import json,sys; d=json.load(open(sys.argv[1])); assert d['points']==16000 and d['level_stats'][-1]['unknowns']==8, d['points']" "$T/upper.json" \
  || fail "decompose O.AMG: $(cat "$T/upper.json")"
"$A" info "$T/O.AMG" | grep "^points *16000$" >/dev/null || fail "info O.AMG"
cp "$T/oct.ply" "$T/OCT.PLY"
"$A" decompose "$T/OCT.PLY" -o "$T/OCT2.AMG" -q || fail "decompose OCT.PLY"
"$A" info "$T/OCT2.AMG" --json | python3 -c "import json,sys; d=json.load(sys.stdin); assert d['points']==16000 and d['frame']['radius']>0, d" \
  || fail "info OCT2.AMG frame"
# a mesh given where points are wanted is told to be sampled
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' > "$T/tri.obj"
expect_fail 1 "amgsplat sample" "$A" decompose "$T/tri.obj" -o "$T/x.amg"
echo "decompose: ok"
