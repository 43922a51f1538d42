# amgsplat info on a small PLY: counts, attributes, bounds; JSON; and errors for bad input.
source "$(dirname "$0")/common.sh"
cat >"$T/tri.ply" <<'PLY'
ply
format ascii 1.0
comment made by info.sh
element vertex 3
property float x
property float y
property float z
property float radius
property uchar quality
end_header
0 0 0 0.5 7
2 0 0 1.5 8
0 4 1 1 9
PLY
"$AMGSPLAT" info "$T/tri.ply" >"$T/out"
grep -q "^points *3$" "$T/out" || fail "point count: $(cat "$T/out")"
grep -q "radii" "$T/out" || fail "radii attribute"
grep -q "quality(uchar)" "$T/out" || fail "extra property"
grep -q "^bbox max *2 4 1$" "$T/out" || fail "bbox: $(cat "$T/out")"
grep -q "radius *mean 1 min 0.5 max 1.5" "$T/out" || fail "radius stats: $(cat "$T/out")"
grep -q "comment *made by info.sh" "$T/out" || fail "comment"
"$AMGSPLAT" info --json "$T/tri.ply" >"$T/json"
python3 -c "import json,sys; d=json.load(open(sys.argv[1])); assert d['points']==3 and d['radii'] and d['bbox_max']==[2,4,1], d" "$T/json" \
  || fail "json: $(cat "$T/json")"
expect_fail 1 "cannot open '$T/missing.ply'" "$AMGSPLAT" info "$T/missing.ply"
expect_fail 2 "expected one file" "$AMGSPLAT" info
echo "info: ok"
