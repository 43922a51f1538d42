# amgsplat fit: a small octahedron level fitted to its own points' splats: the held-out loss falls,
# the silhouette mismatch does not grow, the output reads back with the same primitives, and bad
# options fail with clear messages.
source "$(dirname "$0")/common.sh"
"$AMGSPLAT" fit -h | grep "usage: amgsplat fit" >/dev/null || fail "help"
"$AMGSPLAT" synth octahedron -o "$T/o.ply" --points 4000 --quiet
"$AMGSPLAT" build "$T/o.ply" -o "$T/o.dps" --primitives 40 --quiet >/dev/null
"$AMGSPLAT" fit "$T/o.dps" -o "$T/f.dps" --views 12 --holdout 4 --size 64 --iterations 20 --alpha-rounds 3 \
  --json --threads 2 >"$T/j" 2>"$T/log"
grep "fit: iteration 0: training loss" "$T/log" >/dev/null || fail "no loss on stderr: $(cat "$T/log")"
python3 - "$T/j" <<'PY' || fail "fit json: $(cat "$T/j")"
import json, sys
d = json.load(open(sys.argv[1]))
assert d['reference'].endswith('o.ply') and len(d['levels']) == 1, d
l = d['levels'][0]
assert 0 < l['train_after'] < l['train_before'], l
assert l['holdout_after'] < l['holdout_before'], l
assert 0.5 < l['ssim_before'] <= 1 and l['ssim_after'] >= l['ssim_before'] - 0.01, l
assert l['pixels'] > 1000 and l['texels_seen'] > 100, l
PY
"$AMGSPLAT" info "$T/o.dps" | grep -E "^ +[0-9]+ +L" >"$T/a"
"$AMGSPLAT" info "$T/f.dps" | grep -E "^ +[0-9]+ +L" >"$T/b"
cmp -s <(awk '{print $1, $2, $3, $4}' "$T/a") <(awk '{print $1, $2, $3, $4}' "$T/b") ||
  fail "fitted file has other levels: $(cat "$T/a") / $(cat "$T/b")"
expect_fail 2 "--views and --holdout must be 1 to 256" "$AMGSPLAT" fit "$T/o.dps" -o "$T/x.dps" --views 0
expect_fail 2 "missing -o OUT.dps" "$AMGSPLAT" fit "$T/o.dps"
expect_fail 2 "--alpha-rounds must be 0 to 100" "$AMGSPLAT" fit "$T/o.dps" -o "$T/x.dps" --alpha-rounds -2
expect_fail 1 "cannot open" "$AMGSPLAT" fit "$T/missing.dps" -o "$T/x.dps"
echo ok
