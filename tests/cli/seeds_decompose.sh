#!/usr/bin/env bash
# Seed presets and options of decompose and build (issue 17, docs/seeds.md): --preset sets the seed's
# values, an option given by hand wins wherever it stands, a wrong name is a usage error; the
# unclamped stiffness matrix keeps the positive couplings the default clamps.
source "$(dirname "$0")/common.sh"
A="$AMGSPLAT"
jget() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(eval(sys.argv[2]))" "$@"; }

"$A" decompose -h | grep -- "--preset" >/dev/null || fail "decompose -h lacks --preset"
"$A" build -h | grep -- "--preset" >/dev/null || fail "build -h lacks --preset"
"$A" synth octahedron --points 4000 -o "$T/o.ply" -q >/dev/null

# journal 2.1-2.3: moment classifier, k_min 50 with the whole epsilon-ball, fans from the k-closest set
"$A" decompose "$T/o.ply" -o "$T/j.amg" --preset journal --json >"$T/j.json" 2>"$T/j.err"
[[ $(jget "$T/j.json" "d['k_min'], d['k_max'], d['fan_k']") == "(50, 1024, 50)" ]] || fail "journal sizes: $(cat "$T/j.json")"
grep -F "preset journal: --classifier moment --alpha 0.01 --beta 100" "$T/j.err" >/dev/null || fail "preset line: $(cat "$T/j.err")"
# the journal keeps its positive couplings: the mean neighbourhood is larger than k_min (epsilon-ball)
jget "$T/j.json" "d['mean_neighbourhood'] >= 50 and d['positive_offdiag_clamped'] > 0" | grep True >/dev/null \
  || fail "journal neighbourhood: $(cat "$T/j.json")"
# explicit options win, before or after --preset
"$A" decompose "$T/o.ply" --k 30 --preset journal --fan-k 20 --stats --json -q >"$T/k.json"
[[ $(jget "$T/k.json" "d['k_min'], d['fan_k']") == "(30, 20)" ]] || fail "explicit --k/--fan-k lost: $(cat "$T/k.json")"
"$A" decompose "$T/o.ply" --preset=thesis --stats --json -q >"$T/t.json"
[[ $(jget "$T/t.json" "d['tau'], d['k_min']") == "(0.01, 24)" ]] || fail "thesis tau: $(cat "$T/t.json")"
expect_fail 2 "unknown preset 'seed'" "$A" decompose "$T/o.ply" --stats --preset seed
expect_fail 2 "--stiffness must be clamped or unclamped" "$A" decompose "$T/o.ply" --stats --stiffness maybe

# critical neighbourhood size (thesis 2.3): a flat octahedron face far from its edges sees no jump
"$A" decompose "$T/o.ply" --critical-k >"$T/crit.txt"
grep -E "critical neighbourhood size .*median [0-9]+, 90% 96; [0-9.]+% of the points" "$T/crit.txt" >/dev/null \
  || fail "--critical-k: $(cat "$T/crit.txt")"
expect_fail 2 "--critical-k needs a point input" "$A" decompose "$T/j.amg" --critical-k

# the mesh stiffness matrix (journal eq. 4): a 30 x 30 grid mesh, each cell split in two triangles;
# its vertices are the points, index for index, and an inner vertex's fan is its 6 mesh triangles
python3 - "$T/grid.obj" <<'PY'
import sys
N = 30
with open(sys.argv[1], "w") as f:
    for j in range(N):
        for i in range(N):
            f.write("v %g %g %g\n" % (i / (N - 1), j / (N - 1), 0.3 * abs(i / (N - 1) - 0.5)))
    for j in range(N - 1):
        for i in range(N - 1):
            a = j * N + i + 1
            f.write("f %d %d %d\nf %d %d %d\n" % (a, a + 1, a + N + 1, a, a + N + 1, a + N))
PY
"$A" decompose "$T/grid.obj" --mesh-stiffness -o "$T/grid.amg" --json -q >"$T/grid.json"
jget "$T/grid.json" "d['points'] == 900 and 5.5 < d['mean_fan'] <= 6 and d['levels'] >= 3" | grep True >/dev/null \
  || fail "--mesh-stiffness: $(cat "$T/grid.json")"
"$A" build "$T/grid.amg" -o "$T/grid.dps" --primitives 4 -q >/dev/null || fail "build of a mesh decomposition"
expect_fail 2 "--mesh-stiffness needs a mesh input" "$A" decompose "$T/o.ply" --stats --mesh-stiffness

# the stiffness forms: equal counts of positive couplings, reported as clamped or kept
"$A" decompose "$T/o.ply" -o "$T/c.amg" >"$T/c.txt"
"$A" decompose "$T/o.ply" -o "$T/u.amg" --stiffness unclamped >"$T/u.txt"
nc=$(sed -n 's/.* \([0-9]*\) positive couplings clamped.*/\1/p' "$T/c.txt")
nu=$(sed -n 's/.* \([0-9]*\) positive couplings kept.*/\1/p' "$T/u.txt")
[[ -n "$nc" && "$nc" -gt 0 && "$nc" == "$nu" ]] || fail "positive couplings: '$(cat "$T/c.txt")' vs '$(cat "$T/u.txt")'"
"$A" decompose "$T/u.amg" --stats -q >/dev/null || fail "the unclamped .amg does not load"

# build: the journal's level L-5 (2.3); --primitives by hand replaces the preset's level
"$A" build "$T/j.amg" -o "$T/j.dps" --preset journal -q >/dev/null
"$A" info "$T/j.dps" --json >"$T/ji.json"
[[ $(jget "$T/ji.json" "[l['name'] for l in d['levels']]") == "['L-5']" ]] || fail "journal level: $(cat "$T/ji.json")"
"$A" build "$T/j.amg" -o "$T/p.dps" --preset journal --primitives 30 -q >/dev/null || fail "--primitives with --preset journal"
"$A" info "$T/p.dps" --json >"$T/pi.json"
jget "$T/pi.json" "d['levels'][0]['primitives'] <= 30" | grep True >/dev/null || fail "budget lost: $(cat "$T/pi.json")"
"$A" build "$T/c.amg" -o "$T/t.dps" --preset thesis -q >/dev/null
"$A" info "$T/t.dps" --json >"$T/ti.json"
[[ $(jget "$T/ti.json" "d['method']") == "radial" ]] || fail "thesis method: $(cat "$T/ti.json")"
expect_fail 2 "unknown preset" "$A" build "$T/c.amg" -o "$T/x.dps" --preset Journal
exit 0
