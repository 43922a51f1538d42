# amgsplat synth: every shape writes a readable file with the documented counts; bad input fails cleanly.
source "$(dirname "$0")/common.sh"
"$AMGSPLAT" synth -h | grep "usage: amgsplat synth" >/dev/null || fail "help"
"$AMGSPLAT" synth octahedron -o "$T/oct.ply" --json >"$T/j"
python3 - "$T/j" "$T/oct.ply" <<'PY' || fail "octahedron: $(cat "$T/j")"
import json, sys, struct
d = json.load(open(sys.argv[1]))
assert d["points"] == 16000 and d["labels"] is True and d["shape"] == "octahedron", d
data = open(sys.argv[2], "rb").read()
head, body = data.split(b"end_header\n", 1)
h = head.decode()
assert "element vertex 16000" in h and "property uint label" in h, h
props = [l.split()[1:] for l in h.splitlines() if l.startswith("property")]
fmt = "<" + "".join({"float": "f", "uchar": "B", "uint": "I"}[t] for t, _ in props)
size = struct.calcsize(fmt)
names = [n for _, n in props]
counts = [0] * 8
for i in range(16000):
    rec = dict(zip(names, struct.unpack_from(fmt, body, i * size)))
    x, y, z = rec["x"], rec["y"], rec["z"]
    assert abs(abs(x) + abs(y) + abs(z) - 1) < 1e-5
    lab = (x < 0) | (y < 0) << 1 | (z < 0) << 2
    assert rec["label"] == lab or min(abs(x), abs(y), abs(z)) < 1e-6, rec
    assert rec["radius"] > 0
    counts[rec["label"]] += 1
assert counts == [2000] * 8, counts
PY
"$AMGSPLAT" synth checker-plane -o "$T/checker.ply" | grep "262144 points" >/dev/null || fail "checker-plane count"
"$AMGSPLAT" synth checker-plane --grid 64 --squares 4 -o "$T/small.xyz" -q
[[ $(wc -l <"$T/small.xyz") -eq 4096 ]] || fail "checker-plane 64x64 as xyz"
for s in cube sphere torus; do
  "$AMGSPLAT" synth $s --points 3000 --seed 3 -o "$T/$s.ply" -q || fail "$s"
  grep -aq "element vertex 3000" "$T/$s.ply" || fail "$s count"
done
# same seed, same bytes; another seed, other bytes
"$AMGSPLAT" synth sphere --points 3000 --seed 3 -o "$T/again.ply" -q
cmp -s "$T/sphere.ply" "$T/again.ply" || fail "sphere not deterministic"
"$AMGSPLAT" synth torus --points 3000 --seed 4 -o "$T/other.ply" -q
cmp -s "$T/torus.ply" "$T/other.ply" && fail "seed has no effect"
expect_fail 2 "unknown shape 'dodecahedron'" "$AMGSPLAT" synth dodecahedron -o "$T/x.ply"
expect_fail 2 "missing -o" "$AMGSPLAT" synth cube
expect_fail 2 "expected one shape" "$AMGSPLAT" synth -o "$T/x.ply"
expect_fail 2 "--points expects" "$AMGSPLAT" synth cube --points -5 -o "$T/x.ply"
expect_fail 1 "cube needs 4 to" "$AMGSPLAT" synth cube --points 10 -o "$T/x.ply"
expect_fail 1 "$T/nodir/x.ply" "$AMGSPLAT" synth cube -o "$T/nodir/x.ply"
[[ ! -e "$T/x.ply" ]] || fail "failed runs left an output"
echo "synth: ok"
