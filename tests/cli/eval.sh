#!/usr/bin/env bash
# amgsplat eval on the octahedron: the CSV columns and rows, the JSON, charts and contact
# sheet, the thesis Fig. 1.1 comparison at the 8-domain level, and the error cases.
source "$(dirname "$0")/common.sh"
A="$AMGSPLAT"

"$A" eval -h | grep "usage: amgsplat eval" >/dev/null || fail "help"

"$A" eval octahedron -o "$T/oct" --views 4 --sizes 64,128 --max-primitives 120 --frames 2 -q --json > "$T/run.json"
for f in eval.csv eval.json ssim-64.png ssim-128.png frametime-64.png frametime-128.png sheet.png; do
  [[ -s "$T/oct/$f" ]] || fail "missing $f"
done
head -c 8 "$T/oct/ssim-128.png" | od -c | grep "P   N   G" >/dev/null || fail "chart is not a PNG"
[[ "$(head -1 "$T/oct/eval.csv")" == \
   "representation,level,level_name,size,primitives,drawn,texels,psnr_mean,psnr_min,ssim_mean,ssim_min,iou_mean,iou_min,frame_ms" ]] \
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
