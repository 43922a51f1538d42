# ctest-label: e2e
# amgsplat view / render --frame-ms (issue 18 item 5): the frame budget holds the frame time of a
# scripted fly-through under Xvfb by moving tau, the figures show over the frame (i toggles them),
# renderers without a level of detail say so, and render's simulated budget settles.
#
# Timing on a shared CI machine is noisy, so the target is a quarter of this machine's own
# full-detail frame time (the budget must coarsen to meet it), and the bound is loose (median
# within 35% of T; BENCHMARKS.md "Frame budget" has the 15% figures and the exact commands).
if [[ -z "${ASP_VIEW_UNDER_XVFB:-}" ]] && command -v xvfb-run >/dev/null; then
  ASP_VIEW_UNDER_XVFB=1 exec xvfb-run -a -s "-screen 0 1024x768x24" bash "$0" "$@"
fi
source "$(dirname "$0")/common.sh"
[[ -n "${DISPLAY:-}" ]] || fail "no xvfb-run and no DISPLAY: install xvfb (scripts/bootstrap.sh) to run the viewer tests"
view() { "$AMGSPLAT" view "$@"; }
field() { python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])' "$1" "$2"; }

"$AMGSPLAT" synth sphere -n 200000 -o "$T/s.ply" -q

# Usage errors: a negative budget, --fly against --frames, --overlay with --no-overlay, render's
# budget on a renderer without a level of detail.
expect_fail 2 "--frame-ms expects" view "$T/s.ply" --frame-ms -1 --frames 1
expect_fail 2 "--fly 10 draws 10 frames" view "$T/s.ply" --fly 10 --frames 5
expect_fail 2 "exclude each other" view "$T/s.ply" --overlay --no-overlay --frames 1
expect_fail 2 "--frame-ms needs a renderer with a level of detail" \
  "$AMGSPLAT" render "$T/s.ply" -o "$T/x.png" --frame-ms 40
expect_fail 2 "give no --budget" "$AMGSPLAT" render "$T/s.ply" -o "$T/x.png" --renderer square --budget 100 --frame-ms 40

# This machine's full-detail frame time (square renderer, tau 0, every point), median of 6 frames.
view "$T/s.ply" --renderer square --tau 0 --frames 6 --size 512x512 --json -q >"$T/full.json"
full=$(field "$T/full.json" median_frame_ms)
target=$(awk -v f="$full" 'BEGIN { t = int(f / 4 * 10) / 10; printf "%g", t < 8 ? 8 : t }')
echo "full detail: $full ms per frame; budget $target ms" >&2

# The fly-through under the budget: 120 frames, every frame recorded.
view "$T/s.ply" --renderer square --frame-ms "$target" --fly 120 --size 512x512 --stats-json "$T/fly.json" \
  --screenshot "$T/fly.png" --json -q >"$T/fly_summary.json" || fail "view --fly exited $?"
python3 - "$T/fly.json" "$T/fly_summary.json" "$target" <<'PY' || fail "budget fly-through: $(head -c 600 "$T/fly.json")"
import json, sys, statistics
j, s, target = json.load(open(sys.argv[1])), json.load(open(sys.argv[2])), float(sys.argv[3])
f = j['per_frame']
assert j["frames"] == 120 and len(f) == 120 and j['fly'] and j['budget_applied'], (j['frames'], j['fly'])
assert j['budget_ms'] == target and j['renderer'] == 'square', j['budget_ms']
ms = [x['frame_ms'] for x in f]
med = statistics.median(ms)
assert abs(med - j['median_frame_ms']) < 1e-2 and abs(s['median_frame_ms'] - med) < 1e-2, (med, j['median_frame_ms'])
print('median %.1f ms (p10 %.1f, p90 %.1f), target %.1f, tau %g..%g px, %d..%d points'
      % (med, j['p10_frame_ms'], j['p90_frame_ms'], target, j['tolerance_min'], j['tolerance_max'],
         j['count_min'], j['count_max']), file=sys.stderr)
# the budget holds the frame time (loosely: a shared machine), by moving tau, drawing fewer points
assert abs(med / target - 1) < 0.35, 'median %.1f ms, target %.1f' % (med, target)
assert j['tolerance_max'] > 1.5 * j['tolerance_min'] and j['count_min'] < 0.5 * 200000, (j['tolerance_min'], j['count_min'])
# the path: a full turn, in to 0.35 of the first distance half way, and out again
d = [x['distance'] for x in f]
assert abs(min(d) / d[0] - 0.35) < 0.02 and abs(f[60]["azimuth"] - f[0]['azimuth']) > 170, (min(d), d[0])
# every frame's tau and count are what the frame drew: more points where tau is smaller
lo, hi = min(f[10:], key=lambda x: x['tolerance']), max(f[10:], key=lambda x: x['tolerance'])
assert lo['tolerance'] < hi['tolerance'] and all(x['count'] > 0 and x['frame_ms'] > 0 for x in f)
PY
[[ "$(field "$T/fly_summary.json" title)" == *"| budget $target ms"* ]] || fail "title: $(field "$T/fly_summary.json" title)"

# The figures over the frame: a dark box top-left with the budget on (default), none with
# --no-overlay, and the i key turns them off; the background elsewhere stays white.
check "$T/fly.png" "px(10, 10)[0] < 200 and px(500, 500)[:3] == (255, 255, 255)"
view "$T/s.ply" --renderer square --frame-ms "$target" --frames 3 --no-overlay --size 256x256 --screenshot "$T/no.png" -q
check "$T/no.png" "px(10, 10)[:3] == (255, 255, 255)"
view "$T/s.ply" --renderer square --frame-ms "$target" --frames 3 --keys i --size 256x256 --screenshot "$T/key.png" -q
check "$T/key.png" "px(10, 10)[:3] == (255, 255, 255)"
view "$T/s.ply" --renderer disc --frames 2 --keys i --size 256x256 --screenshot "$T/on.png" -q
check "$T/on.png" "px(10, 10)[0] < 200"

# A renderer without a level of detail: the budget has no effect, said once.
view "$T/s.ply" --renderer disc --frame-ms 10 --frames 4 --size 128x128 --json >"$T/disc.json" 2>"$T/disc.err"
[[ "$(grep -c "has no level of detail" "$T/disc.err")" == 1 ]] || fail "disc budget message: $(cat "$T/disc.err")"
[[ "$(field "$T/disc.json" budget_applied)" == False ]] || fail "disc budget_applied: $(cat "$T/disc.json")"

# render's simulated budget: the same target, settled on one view, the image written.
"$AMGSPLAT" render "$T/s.ply" --renderer square --frame-ms "$target" -o "$T/r.png" --size 512x512 --samples 0 \
  --json >"$T/r.json" || fail "render --frame-ms exited $?"
python3 - "$T/r.json" "$target" <<'PY' || fail "render --frame-ms: $(cat "$T/r.json")"
import json, sys
b, target = json.load(open(sys.argv[1]))['frame_budget'], float(sys.argv[2])
# settling (tau steady and the median within 10% over 9 frames) can take all 200 frames on a loaded
# machine; what counts is where it ended
assert b['target_ms'] == target and 9 <= b['frames'] <= 200, b
assert b['tolerance'] > 0.25 and 0 < b["count"] < 200000, b
assert abs(b['median_ms'] / target - 1) < 0.35, b
PY
[[ -s "$T/r.png" ]] || fail "no image"
