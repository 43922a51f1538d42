# Billboard clouds in the comparisons (issue 30): bench-paper --table 6.1 (domain primitives against a
# billboard cloud at the level's texels and the nearest plane count) and eval's billboards row, on a
# small triangle soup made here. Decomposes (MPI): no leak checks under ASan, like cli.eval.
source "$(dirname "$0")/common.sh"
python3 - "$T" <<'PY'
import math, random, sys
random.seed(5)
v, f = [], []
for c in range(30):   # crossed quads on the ground, like foliage cards
    cx, cz, a = random.uniform(-4, 4), random.uniform(-4, 4), random.uniform(0, math.pi)
    h, w = 1 + random.random(), 0.5 + 0.5 * random.random()
    for q in range(2):
        ang = a + q * math.pi / 2; dx, dz = math.cos(ang) * w, math.sin(ang) * w
        b = len(v) + 1
        v.extend([(cx - dx, 0, cz - dz), (cx + dx, 0, cz + dz), (cx + dx, h, cz + dz), (cx - dx, h, cz - dz)])
        f.extend([(b, b + 1, b + 2), (b, b + 2, b + 3)])
with open(sys.argv[1] + '/soup.obj', 'w') as o:
    for p in v: o.write('v %g %g %g\n' % p)
    for t in f: o.write('f %d %d %d\n' % t)
PY
A=$AMGSPLAT
# thesis Table 6.1 measured (bench-paper --table 6.1) and eval's billboards row, small and fast here
"$A" bench-paper "$T/soup.obj" --table 6.1 --views 2 --sizes 64 --points 3000 --budget 40 --json -q >"$T/t61" \
  || fail "bench-paper --table 6.1"
python3 - "$T/t61" <<'PY' || fail "table 6.1: $(cat "$T/t61")"
import json, sys
d = json.load(open(sys.argv[1]))
rows = d["rows"]
dom = {r["level"]: r for r in rows if r["method"] == "domain"}
bb = {r["level"]: r for r in rows if r["method"] == "billboards"}
assert dom and set(dom) == set(bb), rows
for lv, b in bb.items():
    a = dom[lv]
    # the same texel count (within the sides' rounding) and a plane count near the primitive count
    assert abs(b["texels"] - a["texels"]) <= 0.1 * a["texels"] + 200, (a, b)
    assert abs(b["count"] - a["count"]) <= max(3, 0.5 * a["count"]), (a, b)
    assert 0 < b["error_bound"] < 1 and b["build_seconds"] > 0 and b["iou"] > 0.2, b
assert d["bound_6_percent"]["planes"] >= 6, d
PY
"$A" bench-paper "$T/soup.obj" --table 5.2 >/dev/null 2>"$T/err" && fail "--table 5.2 accepted"
grep "expects 6.1" "$T/err" >/dev/null || fail "--table 5.2: $(cat "$T/err")"
"$A" eval "$T/soup.obj" --methods normalized,billboards --views 2 --sizes 64 --points 3000 --max-primitives 20 \
  -o "$T/ev" -q >/dev/null || fail "eval --methods billboards"
python3 - "$T/ev/eval.csv" <<'PY' || fail "eval billboards rows"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
bb = [r for r in rows if r["representation"] == "billboards"]
dp = [r for r in rows if r["representation"] == "dp-normalized"]
assert bb and len(bb) == len(dp), [r["representation"] for r in rows]
assert all(float(r["iou_mean"]) > 0.2 and int(r["texels"]) > 0 for r in bb), bb
PY
echo ok
