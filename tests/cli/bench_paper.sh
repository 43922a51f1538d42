#!/usr/bin/env bash
# amgsplat bench-paper on the octahedron: the four tables of the seeds (journal Tables 1-2, thesis
# Tables 5.2-5.4) in text, Markdown and JSON, their values' invariants, and the error cases.
source "$(dirname "$0")/common.sh"
A="$AMGSPLAT"

"$A" bench-paper -h >"$T/help.txt"
grep "usage: amgsplat bench-paper" "$T/help.txt" >/dev/null || fail "help"

"$A" bench-paper octahedron --sizes 64 --frames 2 --json -q >"$T/b.json"
python3 - "$T/b.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
assert d["model"] == "octahedron" and d["points"] == 16000 and d["sizes"] == [64], d
assert d["fps_method"] == "overlap" and len(d["fps_points"]) == 1 and d["fps_points"][0] > 0
levels = d["levels"]
names = [l["name"] for l in levels]
assert names[0] == "L" and levels[0]["primitives"] == 8, names  # the coarsest level: the 8 faces
# Table 5.2: polygons grow towards the finer levels, every level has texels and a frame rate
for a, b in zip(levels, levels[1:]):
    assert b["primitives"] > a["primitives"], (a["name"], b["name"])
    assert b["texels"] >= a["texels"] * 0.9, (a["name"], b["name"])
for l in levels:
    assert l["primitives"] <= 2000 and l["texels"] > 0 and len(l["fps"]) == 1 and l["fps"][0] > 0, l
    # flat faces: the planes fit within a hundredth of a point radius on average
    assert 0 <= l["normalised_error"] < 0.02, l
# Table 1 / 5.3 / 5.4 level: the finest with at most 500 primitives
budget = [l for l in levels if l["name"] == d["budget_level"]][0]
assert budget["primitives"] <= 500 and all(l["primitives"] > 500 for l in levels if l["level"] < budget["level"]), d["budget_level"]
# Table 5.4: texel sizes 2, 1, 0.5; texels about 4x per halving (thesis: 66 k / 255 k / 1083 k)
tm = d["texture_methods"]
assert [t["texel_size"] for t in tm] == [2, 1, 0.5], tm
assert tm[1]["texels"] == budget["texels"], (tm[1], budget)
for a, b in zip(tm, tm[1:]):
    assert 3.0 < b["texels"] / a["texels"] < 5.0, (a, b)
for t in tm:
    assert all(t[k] > 0 for k in ("constant", "linear", "gaussian", "linear_affine")), t
PY

# the text tables, and Markdown for docs/results.md
"$A" bench-paper octahedron --sizes 64 --frames 1 --no-texture-methods >"$T/b.txt"
for title in "Journal Table 1" "Journal Table 2 / thesis Table 5.2" "Thesis Table 5.3"; do
  grep -F "$title" "$T/b.txt" >/dev/null || fail "missing '$title': $(cat "$T/b.txt")"
done
grep -F "Thesis Table 5.4" "$T/b.txt" >/dev/null && fail "--no-texture-methods printed Table 5.4"
grep -E "^octahedron +16000 +L-[0-9]+ +[0-9]+ " "$T/b.txt" >/dev/null || fail "Table 1 row: $(cat "$T/b.txt")"
"$A" bench-paper octahedron --sizes 64 --frames 1 --no-texture-methods --markdown -q >"$T/b.md"
grep -E "^\| octahedron \| 16000 \| L-[0-9]+ \|" "$T/b.md" >/dev/null || fail "Markdown Table 1: $(cat "$T/b.md")"
grep -E "^\| 10 \| L \| 8 \|" "$T/b.md" >/dev/null || fail "Markdown Table 5.2, level L: $(cat "$T/b.md")"

# errors: usage (2) and run-time (1)
expect_fail 2 "expected one MODEL" "$A" bench-paper
expect_fail 2 "--sizes expects" "$A" bench-paper octahedron --sizes 8
expect_fail 2 "at least 1" "$A" bench-paper octahedron --budget 0
expect_fail 1 "missing.ply" "$A" bench-paper "$T/missing.ply"
echo "bench-paper: ok"
