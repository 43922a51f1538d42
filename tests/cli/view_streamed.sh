# ctest-label: e2e
# amgsplat view on a streamed .hier (amgsplat convert; docs/cli/view.md "Streamed hierarchies"): the
# first view's cut under --memory, the same picture as `amgsplat render` of that file, a new cut
# once the camera rests after zooming in (more points, still within the budget), the tau keys
# steering the cut, and option errors.
if [[ -z "${ASP_VIEW_UNDER_XVFB:-}" ]] && command -v xvfb-run >/dev/null; then
  ASP_VIEW_UNDER_XVFB=1 exec xvfb-run -a -s "-screen 0 1024x768x24" bash "$0" "$@"
fi
source "$(dirname "$0")/common.sh"
[[ -n "${DISPLAY:-}" ]] || fail "no xvfb-run and no DISPLAY: install xvfb (scripts/bootstrap.sh) to run the viewer tests"

"$AMGSPLAT" synth terrain --points 200000 -o "$T/site.ply" -q
"$AMGSPLAT" convert "$T/site.ply" -o "$T/site.hier" --node-points 4096 -q || fail "convert exited $?"

# 1. the first view: its cut within --memory (64 bytes a point: 2M -> 32768 points), the same
#    picture as render draws of the same file at the same view
"$AMGSPLAT" view "$T/site.hier" --frames 2 --size 240x180 --view 30,30 --memory 2M --screenshot "$T/v.png" --json \
  >"$T/v.json" 2>"$T/v.err" || fail "view exited $?: $(cat "$T/v.err")"
"$AMGSPLAT" render "$T/site.hier" -o "$T/r.png" --size 240x180 --view 30,30 --memory 2M -q ||
  fail "render exited $?"
python3 - "$T/v.json" <<'PY' || fail "first cut: $(cat "$T/v.json")"
import json, sys
j = json.load(open(sys.argv[1]))
assert j['stream_point_count'] == 200000, j
assert j['stream_loads'] == 1, j               # the camera never moved: one cut
assert 0 < j['stream_points'] <= 2 * 1024 * 1024 // 64, j
assert j['count'] == j['stream_points'] and j['renderer'] == 'disc' and j['edl'], j
assert 'streamed: %d of 200000 points' % j['stream_points'] in j['title'], j['title']
PY
"$AMGSPLAT" imgdiff "$T/v.png" "$T/r.png" --json >"$T/d.json" || fail "imgdiff exited $?"
python3 -c "
import json, sys
d = json.load(open(sys.argv[1]))
print('view vs render of the streamed file: SSIM %.4f' % d['ssim'])
assert d['ssim'] >= 0.95, d" "$T/d.json" || fail "view and render of the first cut differ: $(cat "$T/d.json")"

# 2. zooming in: once the camera rests the view's cut is loaded again; closer, it holds finer
#    nodes (more of the points under the same budget at full memory) and the picture changes
"$AMGSPLAT" view "$T/site.hier" --frames 10 --size 240x180 --view 30,30 --memory 64M --keys zzzzzz \
  --screenshot "$T/z.png" --json >"$T/z.json" 2>"$T/z.err" || fail "view (zoom) exited $?: $(cat "$T/z.err")"
"$AMGSPLAT" view "$T/site.hier" --frames 2 --size 240x180 --view 30,30 --memory 64M --json >"$T/f.json" 2>/dev/null ||
  fail "view (far) exited $?"
python3 - "$T/z.json" "$T/f.json" <<'PY' || fail "zoomed cut: $(cat "$T/z.json" "$T/f.json")"
import json, sys
z, f = (json.load(open(p)) for p in sys.argv[1:3])
assert z['stream_loads'] == 2, z            # the first view, then the rested zoomed one
assert z['stream_points'] > f['stream_points'], (z['stream_points'], f['stream_points'])
assert z['stream_points'] <= 64 * 1024 * 1024 // 64 and z['count_max'] == z['stream_points'], z
assert z['count_min'] == f['stream_points'], (z, f)
PY
grep -q "streamed: " "$T/z.err" || fail "the new cut was not reported: $(cat "$T/z.err")"

# 3. tau steers the cut: a coarser tolerance (+ keys) shows fewer points
"$AMGSPLAT" view "$T/site.hier" --frames 8 --size 240x180 --view 30,30 --keys "++++" --json >"$T/t.json" \
  2>/dev/null || fail "view (tau) exited $?"
python3 - "$T/t.json" "$T/f.json" <<'PY' || fail "tau: $(cat "$T/t.json")"
import json, sys
t, f = (json.load(open(p)) for p in sys.argv[1:3])
assert t['stream_loads'] >= 2 and t['stream_points'] < f['stream_points'], (t, f)
PY

# 4. errors: --memory names a streamed .hier; a bad size is a usage error
rc=0; "$AMGSPLAT" view "$T/site.ply" --frames 1 --memory 1G 2>"$T/e1" || rc=$?
[[ $rc == 2 ]] && grep -q "streamed .hier" "$T/e1" || fail "--memory on a point file: exit $rc, $(cat "$T/e1")"
rc=0; "$AMGSPLAT" view "$T/site.hier" --frames 1 --memory lots 2>"$T/e2" || rc=$?
[[ $rc == 2 ]] && grep -q -- "--memory expects" "$T/e2" || fail "--memory lots: exit $rc, $(cat "$T/e2")"
head -c 3000 "$T/site.hier" >"$T/cut.hier"
rc=0; "$AMGSPLAT" view "$T/cut.hier" --frames 1 2>"$T/e3" || rc=$?
[[ $rc != 0 && $rc -lt 128 ]] && grep -q "cut.hier" "$T/e3" || fail "truncated streamed .hier: exit $rc, $(cat "$T/e3")"
echo "ok"
