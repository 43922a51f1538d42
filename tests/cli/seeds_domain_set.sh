#!/usr/bin/env bash
# Domain Set (thesis appendix C, issue 17): `build --domains both` puts the thresholded and the strict
# primitives of each level in one .dps; `render --domains` picks the set, the strict one drawn with the
# no-blend method unless --method says otherwise.
source "$(dirname "$0")/common.sh"
A="$AMGSPLAT"
mpi_asan="${ASAN_OPTIONS:-}:fast_unwind_on_malloc=0" # decompose/build start MPI (see seeds_render.sh)
jget() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(eval(sys.argv[2]))" "$@"; }

"$A" synth octahedron --points 3000 -o "$T/o.ply" -q
ASAN_OPTIONS="$mpi_asan" "$A" decompose "$T/o.ply" -o "$T/o.amg" -q
st=0
ASAN_OPTIONS="$mpi_asan" "$A" build "$T/o.amg" -o "$T/b.dps" --level L-3,L-2 --domains both --json >"$T/b.json" 2>"$T/b.err" || st=$?
if ((st != 0)) && grep -F "does not read back" "$T/b.err" >/dev/null; then
  # the .dps of this branch cannot hold one AMG level twice yet (asp_dps_level.strict is persisted by
  # .dps version 3, src/prim/dps_file.c)
  echo "SKIPPED: the .dps format does not store strict levels yet: $(cat "$T/b.err")" >&2
  exit 77
fi
((st == 0)) || fail "build --domains both: $(cat "$T/b.err")"
python3 - "$T/b.json" <<'PY' || fail "build --domains both: $(cat "$T/b.json")"
import json, sys
lv = json.load(open(sys.argv[1]))["levels"]
assert [l["domains"] for l in lv] == ["thresholded", "strict"] * 2, lv
assert lv[0]["level"] == lv[1]["level"] and lv[2]["level"] == lv[3]["level"], lv
PY
R=(--size 96x96 --view 30,20 -q --json)
"$A" render "$T/b.dps" -o "$T/t.png" "${R[@]}" >"$T/t.json"
"$A" render "$T/b.dps" -o "$T/s.png" --domains strict "${R[@]}" >"$T/s.json"
"$A" render "$T/b.dps" -o "$T/sn.png" --domains strict --method normalized "${R[@]}" >"$T/sn.json"
"$A" render "$T/b.dps" -o "$T/s2.png" --domains strict --level L-2 "${R[@]}" >"$T/s2.json"
[[ $(jget "$T/t.json" "d['domains'], d['method']") == "('thresholded', 'normalized')" ]] || fail "default set: $(cat "$T/t.json")"
[[ $(jget "$T/s.json" "d['domains'], d['method']") == "('strict', 'no-blend')" ]] || fail "strict set: $(cat "$T/s.json")"
[[ $(jget "$T/sn.json" "d['domains'], d['method']") == "('strict', 'normalized')" ]] || fail "--method lost: $(cat "$T/sn.json")"
[[ $(jget "$T/s2.json" "d['domains']") == "strict" ]] || fail "--level L-2 strict"
[[ $(jget "$T/s2.json" "d['level']") != $(jget "$T/s.json" "d['level']") ]] || fail "--level ignored with --domains"
# the two sets of one file: other pixels, one silhouette
! cmp -s "$T/t.png" "$T/s.png" || fail "the strict set drew the thresholded set's pixels"
"$A" imgdiff "$T/t.png" "$T/s.png" --json | python3 -c "import json,sys; d=json.load(sys.stdin); assert d['iou'] > 0.9, d" \
  || fail "the sets' silhouettes differ"
# the same pixels as a file of the strict set alone
ASAN_OPTIONS="$mpi_asan" "$A" build "$T/o.amg" -o "$T/so.dps" --level L-3 --domains strict -q >/dev/null
"$A" render "$T/so.dps" -o "$T/so.png" --method no-blend "${R[@]}" >/dev/null
cmp -s "$T/so.png" "$T/s.png" || fail "--domains strict of a both file differs from a strict build"
expect_fail 1 "no thresholded levels in the file" "$A" render "$T/so.dps" -o "$T/x.png" --domains thresholded
expect_fail 2 "--domains expects thresholded or strict" "$A" render "$T/b.dps" -o "$T/x.png" --domains both
