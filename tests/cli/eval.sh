#!/usr/bin/env bash
# amgsplat eval on the octahedron: the CSV columns and rows, the JSON, charts and contact
# sheet, the thesis Fig. 1.1 comparison at the 8-domain level, and the error cases; on a mesh
# (a UV sphere made here): the mesh reference and the simplified-mesh rows of issue 14.
source "$(dirname "$0")/common.sh"
A="$AMGSPLAT"

"$A" eval -h | grep "usage: amgsplat eval" >/dev/null || fail "help"

"$A" eval octahedron -o "$T/oct" --views 4 --sizes 64,128 --max-primitives 120 --frames 2 -q --json > "$T/run.json"
for f in eval.csv eval.json ssim-64.png ssim-128.png frametime-64.png frametime-128.png sheet.png; do
  [[ -s "$T/oct/$f" ]] || fail "missing $f"
done
head -c 8 "$T/oct/ssim-128.png" | od -c | grep "P   N   G" >/dev/null || fail "chart is not a PNG"
[[ "$(head -1 "$T/oct/eval.csv")" == \
   "representation,level,level_name,size,primitives,drawn,texels,psnr_mean,psnr_min,ssim_mean,ssim_min,iou_mean,iou_min,frame_ms,bytes,note" ]] \
  || fail "CSV header: $(head -1 "$T/oct/eval.csv")"

python3 - "$T/oct/eval.csv" "$T/oct/eval.json" "$T/run.json" <<'PY'
import csv, json, sys
rows = list(csv.DictReader(open(sys.argv[1])))
ev = json.load(open(sys.argv[2]))
run = json.load(open(sys.argv[3]))
assert len(rows) == len(ev["rows"]) == run["rows"], (len(rows), run["rows"])
assert ev["points"] == 16000 and ev["views"] == 4
# the reference's splats are clipped at the creases: the points within a splat of an edge
assert ev["crease_angle"] == 60 and 1000 < ev["clipped_points"] < 8000, ev["clipped_points"]
reps = sorted({r["representation"] for r in rows})
assert reps == ["dp-normalized", "dp-overlap", "dp-prefix", "dp-two-pass", "points", "reference"], reps
for size in ("64", "128"):
    sub = [r for r in rows if r["size"] == size]
    ref = [r for r in sub if r["representation"] == "reference"]
    assert len(ref) == 1 and float(ref[0]["ssim_mean"]) == 1.0 and int(ref[0]["primitives"]) == 16000
    levels = {r["level_name"] for r in sub if r["representation"] == "points"}
    assert len(sub) == 1 + 5 * len(levels), (size, len(sub), levels)
    for r in sub:
        p = int(r["primitives"]); d = float(r["drawn"])
        assert p <= 120 or r["representation"] == "reference", r
        assert 0 <= float(r["ssim_min"]) <= float(r["ssim_mean"]) <= 1, r
        assert 0 <= float(r["iou_min"]) <= float(r["iou_mean"]) <= 1, r
        assert float(r["frame_ms"]) > 0, r
        if r["representation"] == "points":
            # the splat budget: the level's primitive count, short of it by less than one expansion (8)
            assert p - 8 < d <= p, ("cut far from its target", r)
            assert int(r["texels"]) == 0
        elif r["representation"].startswith("dp-"):
            assert d == p and int(r["texels"]) > 0, r
    # the 8-domain level: every face one primitive
    eight = [r for r in sub if r["primitives"] == "8"]
    assert len(eight) == 5, eight
    pts = [r for r in eight if r["representation"] == "points"][0]
    dps = [r for r in eight if r["representation"].startswith("dp-")]
    best = max(float(r["ssim_mean"]) for r in dps)
    # issue 7: >= 0.95 against the crease-clipped splat reference (docs/cli/eval.md)
    print("8-domain level, %s px: best SSIM %.4f" % (size, best))
    assert best >= (0.95 if size == "128" else 0.93), (size, best)
    assert all(float(r["ssim_mean"]) > float(pts["ssim_mean"]) + 0.2 for r in dps), (size, eight)
    assert min(float(r["iou_mean"]) for r in dps) >= 0.9, eight
claims = [c for c in run["claim"] if c["primitives"] == 8]
assert len(claims) == 2 and all(c["wins"] == 4 for c in claims), claims
PY

# a mesh: the reference is its own render; full point set, cut, primitives, and the two simplified meshes
python3 - "$T/sphere.obj" "$T/tex.png" <<'PY'
import math, struct, sys, zlib
nu, nv = 32, 16
with open(sys.argv[1], "w") as f:
    for j in range(nv + 1):
        th = math.pi * j / nv
        for i in range(nu + 1):
            ph = 2 * math.pi * i / nu
            f.write("v %f %f %f\nvt %f %f\n" % (math.sin(th) * math.cos(ph), math.cos(th),
                                                 math.sin(th) * math.sin(ph), i / nu, 1 - j / nv))
    for j in range(nv):
        for i in range(nu):
            a = j * (nu + 1) + i + 1; b = a + 1; c = a + nu + 1; d = c + 1
            if j > 0: f.write("f %d/%d %d/%d %d/%d\n" % (a, a, c, c, b, b))
            if j < nv - 1: f.write("f %d/%d %d/%d %d/%d\n" % (b, b, c, c, d, d))
# a 1024 x 1024 checker texture: 5.6 MB with mipmaps, more than any level of primitives
w = 1024
raw = b"".join(b"\0" + bytes((200 if ((x // 64 + y // 64) % 2) else 60) for x in range(w) for _ in range(3))
               for y in range(w))
chunk = lambda t, d: struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d))
open(sys.argv[2], "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, w, 8, 2, 0, 0, 0))
                              + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
PY
"$A" eval "$T/sphere.obj" -o "$T/mesh" --views 2 --sizes 64 --max-primitives 120 --methods normalized \
  --points 8000 --frames 1 -q --json > "$T/mesh.json"
for f in eval.csv eval.json ssim-64.png frametime-64.png sheet.png; do
  [[ -s "$T/mesh/$f" ]] || fail "mesh eval: missing $f"
done
"$A" simplify "$T/sphere.obj" --triangles 959 -o "$T/copy.obj" --json > "$T/full.json"
# every mesh-tris row against `amgsplat simplify --sloppy` at the same target (the first eval tries)
python3 - "$T/mesh/eval.csv" "$T/mesh/eval.json" "$T/full.json" <<'PY' > "$T/targets"
import csv, json, sys
rows = list(csv.DictReader(open(sys.argv[1])))
ev = json.load(open(sys.argv[2]))
full = json.load(open(sys.argv[3]))
assert ev["mesh_triangles"] == 960, ev["mesh_triangles"]
reps = [r["representation"] for r in rows]
assert reps[:3] == ["reference", "full-discs", "full-splats"], reps[:3]
assert sorted(set(reps)) == ["dp-normalized", "full-discs", "full-splats", "mesh-bytes", "mesh-tris", "points",
                             "reference"], reps
ref = rows[0]
assert ref["level_name"] == "mesh" and int(ref["primitives"]) == 960 and float(ref["ssim_mean"]) == 1.0, ref
assert int(ref["bytes"]) == full["input_bytes"]["total"], (ref["bytes"], full["input_bytes"])
for r in rows[1:3]:
    # 8000 discs or splats of a sphere against its own render: close but not identical
    assert int(r["primitives"]) == 8000 and int(r["bytes"]) == 8000 * 32, r
    assert 0.9 < float(r["ssim_mean"]) < 1 and float(r["iou_mean"]) > 0.97, r
levels = {r["level_name"]: r for r in rows if r["representation"] == "dp-normalized"}
assert len(levels) >= 2, levels
for r in rows:
    if r["note"]:
        continue
    assert 0 < float(r["ssim_min"]) <= float(r["ssim_mean"]) <= 1, r
    assert 0 <= float(r["iou_min"]) <= float(r["iou_mean"]) <= 1 and float(r["frame_ms"]) > 0, r
# the claim compares the best method with both simplified meshes, where they exist
claim = json.load(open(sys.argv[1].replace("eval.csv", "../mesh.json")))["claim"]
assert len(claim) == len(levels) and all("mesh_bytes_ssim" in c for c in claim), claim
assert any("mesh_tris_ssim" in c and 0 <= c["wins_mesh_tris"] <= 2 for c in claim), claim
for r in rows:
    lv = levels.get(r["level_name"])
    if r["representation"] == "mesh-tris" and r["note"]:
        # meshoptimizer keeps the UV seam: the coarsest levels are out of reach, and the row says so
        n = r["note"].split()
        assert n[:2] == ["smallest", "simplification"] and int(n[2]) > int(r["primitives"]), r
        assert r["ssim_mean"] == "" and float(r["drawn"]) == 0, r
    elif r["representation"] == "mesh-tris":
        assert int(r["primitives"]) == int(lv["primitives"]) and 0 < float(r["drawn"]) <= int(r["primitives"]), r
        print(r["primitives"], r["drawn"].split(".")[0], r["bytes"])
    if r["representation"] == "mesh-bytes":
        assert not r["note"], r
        # at most the level's bytes; the sphere's 960 triangles take 38 kB, less than the primitives' atlases
        assert 0 < int(r["bytes"]) <= int(lv["bytes"]), (r, lv)
        assert float(r["drawn"]) == 960 and float(r["ssim_mean"]) == 1.0, r
PY
[[ -s "$T/targets" ]] || fail "no mesh-tris rows"
while read -r n tris bytes; do
  "$A" simplify "$T/sphere.obj" --triangles "$n" --sloppy -o "$T/s$n.obj" --json > "$T/s$n.json"
  python3 -c '
import json, sys
j = json.load(open(sys.argv[1])); n, tris, b = map(int, sys.argv[2:])
if j["triangles"] <= n:  # otherwise eval bisected to a smaller target
    assert j["triangles"] == tris and j["bytes"]["total"] == b, (j, tris, b)' "$T/s$n.json" "$n" "$tris" "$bytes" \
    || fail "mesh-tris at $n: bytes are not asp_mesh_gpu_bytes"
done < "$T/targets"

# a texture larger than every level's bytes: the equal-bytes row says so instead of showing a mesh
"$A" eval "$T/sphere.obj" --texture "$T/tex.png" -o "$T/tex" --views 1 --sizes 32 --max-primitives 40 \
  --methods normalized --points 4000 --frames 1 -q > /dev/null
python3 - "$T/tex/eval.csv" <<'PY'
import csv, sys
rows = [r for r in csv.DictReader(open(sys.argv[1])) if r["representation"] == "mesh-bytes"]
assert rows and all(r["note"].startswith("texture alone 5592405 bytes exceeds") and r["ssim_mean"] == ""
                    for r in rows), rows
PY

# text output: the table and the comparison
"$A" eval octahedron -o "$T/txt" --views 2 --sizes 32 --max-primitives 10 --methods prefix --frames 1 > "$T/out.txt"
grep -q "^representation .* frame ms" "$T/out.txt" || fail "table header: $(cat "$T/out.txt")"
grep -Eq "^dp-prefix +L +32 +8 " "$T/out.txt" || fail "dp row: $(cat "$T/out.txt")"
grep -q "best domain-primitive method against the point cut" "$T/out.txt" || fail "comparison"
[[ $(grep -c "^dp-" "$T/txt/eval.csv") -ge 1 && $(grep -c "^dp-overlap" "$T/txt/eval.csv") -eq 0 ]] \
  || fail "--methods prefix not honoured"

# errors: usage (2) and run-time (1)
expect_fail 2 "expected one MODEL" "$A" eval
expect_fail 2 "--sizes expects" "$A" eval octahedron --sizes 8
expect_fail 2 "--sizes expects" "$A" eval octahedron --sizes 64,abc
expect_fail 2 "--methods" "$A" eval octahedron --methods nonsense
expect_fail 2 "--views expects" "$A" eval octahedron --views 0
expect_fail 2 "--crease-angle expects" "$A" eval octahedron --crease-angle 95
expect_fail 2 "--crease-angle expects" "$A" eval octahedron --crease-angle sharp
expect_fail 1 "missing.ply" "$A" eval "$T/missing.ply" -o "$T/x"
expect_fail 1 "applies to meshes only" "$A" eval octahedron --texture x.png -o "$T/x"
printf 'ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nend_header\n1\n' > "$T/bad.ply"
expect_fail 1 "bad.ply" "$A" eval "$T/bad.ply" -o "$T/x"
echo "eval: ok"
