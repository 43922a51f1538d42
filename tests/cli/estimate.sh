# amgsplat estimate: outward normals and positive radii on a raw sphere scan, viewpoint
# orientation, kept attributes, JSON, and clean failures with the documented exit codes.
source "$(dirname "$0")/common.sh"
"$AMGSPLAT" estimate -h | grep "usage: amgsplat estimate" >/dev/null || fail "help"

# a raw scan: 4000 random points on a sphere of radius 2 around (10, -5, 3), positions only
python3 - "$T/scan.xyz" <<'PY'
import math, random, sys
random.seed(7)
with open(sys.argv[1], "w") as f:
    for _ in range(4000):
        z = random.uniform(-1, 1); a = random.uniform(0, 2 * math.pi); s = math.sqrt(1 - z * z)
        f.write("%.7f %.7f %.7f\n" % (10 + 2 * s * math.cos(a), -5 + 2 * s * math.sin(a), 3 + 2 * z))
PY

# reads a PLY (ascii or binary little endian) vertex element into a list of dicts
cat >"$T/ply.py" <<'PY'
import struct
def read(path):
    data = open(path, "rb").read()
    head, body = data.split(b"end_header\n", 1)
    lines = head.decode().splitlines()
    fmt = [l.split()[1] for l in lines if l.startswith("format")][0]
    n = int([l.split()[2] for l in lines if l.startswith("element vertex")][0])
    props = [l.split()[1:] for l in lines if l.startswith("property")]
    names = [p[1] for p in props]
    if fmt == "ascii":
        rows = body.decode().split("\n")[:n]
        return [dict(zip(names, map(float, r.split()))) for r in rows]
    code = {"float": "f", "double": "d", "uchar": "B", "uint": "I", "int": "i", "float32": "f", "uint8": "B"}
    f = "<" + "".join(code[t] for t, _ in props)
    size = struct.calcsize(f)
    return [dict(zip(names, struct.unpack_from(f, body, i * size))) for i in range(n)]
PY

"$AMGSPLAT" estimate "$T/scan.xyz" -o "$T/out.ply" --json >"$T/j"
python3 - "$T/j" "$T/out.ply" "$T" <<'PY' || fail "default estimate: $(cat "$T/j")"
import json, math, sys
sys.path.insert(0, sys.argv[3]); import ply
d = json.load(open(sys.argv[1]))
assert d["points"] == 4000 and d["normals"] == "estimated" and d["radii"] == "estimated", d
v = ply.read(sys.argv[2])
assert len(v) == 4000
worst = 0
for p in v:
    r = (p["x"] - 10, p["y"] + 5, p["z"] - 3)
    l = math.sqrt(sum(c * c for c in r))
    dot = (p["nx"] * r[0] + p["ny"] * r[1] + p["nz"] * r[2]) / l
    assert dot > 0, ("inward normal", p)
    worst = max(worst, math.degrees(math.acos(min(1, dot))))
    assert 0 < p["radius"] < 1, p
assert worst < 5, worst
PY

# towards the centre: every normal points inwards; only normals are added
"$AMGSPLAT" estimate "$T/scan.xyz" -o "$T/in.ply" --normals --orient-to 10,-5,3 -q
python3 - "$T/in.ply" "$T" <<'PY' || fail "--orient-to"
import sys
sys.path.insert(0, sys.argv[2]); import ply
v = ply.read(sys.argv[1])
assert "radius" not in v[0], v[0]
assert all(p["nx"] * (p["x"] - 10) + p["ny"] * (p["y"] + 5) + p["nz"] * (p["z"] - 3) < 0 for p in v)
PY

# existing normals are kept without --force, replaced (with kept signs) with it
"$AMGSPLAT" estimate "$T/in.ply" -o "$T/kept.ply" --json >"$T/j2"
grep -q '"normals": "kept"' "$T/j2" || fail "normals not kept: $(cat "$T/j2")"
grep -q '"radii": "estimated"' "$T/j2" || fail "radii not added: $(cat "$T/j2")"
"$AMGSPLAT" estimate "$T/in.ply" -o "$T/forced.ply" --normals --force --keep-orientation -q
python3 - "$T/forced.ply" "$T" <<'PY' || fail "--keep-orientation"
import sys
sys.path.insert(0, sys.argv[2]); import ply
v = ply.read(sys.argv[1])
assert all(p["nx"] * (p["x"] - 10) + p["ny"] * (p["y"] + 5) + p["nz"] * (p["z"] - 3) < 0 for p in v)
PY
"$AMGSPLAT" estimate "$T/scan.xyz" -o "$T/human.ply" --radii | grep "4000 points, normals none, radii estimated" >/dev/null ||
  fail "human output"

# failures
printf '1 2 3\n1 2 3\n1 2 3\n1 2 3\n' >"$T/same.xyz"
printf '0 0 0\n1 0 0\n' >"$T/two.xyz"
expect_fail 1 "all 4 points are equal" "$AMGSPLAT" estimate "$T/same.xyz" -o "$T/x.ply"
expect_fail 1 "need at least 3" "$AMGSPLAT" estimate "$T/two.xyz" -o "$T/x.ply"
expect_fail 1 "$T/missing.xyz" "$AMGSPLAT" estimate "$T/missing.xyz" -o "$T/x.ply"
expect_fail 1 "$T/nodir/x.ply" "$AMGSPLAT" estimate "$T/scan.xyz" -o "$T/nodir/x.ply"
expect_fail 2 "missing -o" "$AMGSPLAT" estimate "$T/scan.xyz"
expect_fail 2 "expected one input" "$AMGSPLAT" estimate -o "$T/x.ply"
expect_fail 2 "--orient-to expects x,y,z" "$AMGSPLAT" estimate "$T/scan.xyz" -o "$T/x.ply" --orient-to 1,2
expect_fail 2 "--k expects 1..1024, got 0" "$AMGSPLAT" estimate "$T/scan.xyz" -o "$T/x.ply" --k 0
expect_fail 2 "--radius-factor" "$AMGSPLAT" estimate "$T/scan.xyz" -o "$T/x.ply" --radius-factor -1
expect_fail 2 "--keep-orientation needs normals" "$AMGSPLAT" estimate "$T/scan.xyz" -o "$T/x.ply" --force --keep-orientation
[[ ! -e "$T/x.ply" ]] || fail "failed runs left an output"
echo "estimate: ok"
