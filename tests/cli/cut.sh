# The cut across .dps levels (issue 18, docs/cut.md): build stores linked levels and every build
# option (info shows them), render --renderer cut mixes the levels by --tolerance (0 = the finest
# level, huge = the coarsest), and refuses what it cannot draw.
source "$(dirname "$0")/common.sh"

mpi_asan="${ASAN_OPTIONS:-}:fast_unwind_on_malloc=0"
"$AMGSPLAT" synth torus -o "$T/t.ply" -q
ASAN_OPTIONS="$mpi_asan" "$AMGSPLAT" decompose "$T/t.ply" -o "$T/t.amg" -q
ASAN_OPTIONS="$mpi_asan" "$AMGSPLAT" build "$T/t.amg" -o "$T/t.dps" --level L-6..L-3 --brightness 0.1 -q >/dev/null
ASAN_OPTIONS="$mpi_asan" "$AMGSPLAT" build "$T/t.amg" -o "$T/one.dps" --level L-4 -q >/dev/null

"$AMGSPLAT" info "$T/t.dps" >"$T/info"
grep -F "links       yes" "$T/info" >/dev/null || fail "info: $(cat "$T/info")"
grep -F "brightness 0.1" "$T/info" >/dev/null || fail "info lacks the build options: $(cat "$T/info")"
"$AMGSPLAT" info "$T/t.dps" --json >"$T/info.json"
python3 -c "
import json, sys
d = json.load(open(sys.argv[1]))
assert d['links'] is True and d['build']['brightness'] == 0.1 and d['build']['domains'] == 'thresholded', d['build']
lv = d['levels']
assert len(lv) == 4 and all(l['links'] > 0 for l in lv[:3]) and lv[3]['links'] == 0, lv
" "$T/info.json" || fail "info json: $(cat "$T/info.json")"
counts=$(python3 -c "
import json, sys
lv = json.load(open(sys.argv[1]))['levels']
print(lv[0]['primitives'], lv[-1]['primitives'])" "$T/info.json")
read -r finest coarsest <<<"$counts"

# tolerance 0: the finest level everywhere; a huge one: the coarsest; 2 px: a mix in between
drawn() { python3 -c "import json, sys; print(json.load(open(sys.argv[1]))['primitives'])" "$1"; }
"$AMGSPLAT" render "$T/t.dps" --renderer cut --tolerance 0 -o "$T/c0.png" --size 96x96 --json >"$T/c0.json"
[[ $(drawn "$T/c0.json") -eq $finest ]] || fail "tolerance 0 drew $(drawn "$T/c0.json"), expected $finest"
python3 -c "
import json, sys
d = json.load(open(sys.argv[1]))
assert d['renderer'] == 'cut' and d['tolerance'] == 0, d" "$T/c0.json" || fail "json: $(cat "$T/c0.json")"
check "$T/c0.png" "px(48, 48) == (255, 255, 255, 255) and px(48, 20)[:3] != (255, 255, 255)"
"$AMGSPLAT" render "$T/t.dps" --renderer cut --tolerance 100000 -o "$T/cL.png" --size 96x96 --json >"$T/cL.json"
[[ $(drawn "$T/cL.json") -eq $coarsest ]] || fail "a huge tolerance drew $(drawn "$T/cL.json"), expected $coarsest"
"$AMGSPLAT" render "$T/t.dps" --renderer cut --tolerance 2 -o "$T/c2.png" --size 96x96 --json >"$T/c2.json"
mid=$(drawn "$T/c2.json")
((mid > coarsest && mid < finest)) || fail "tolerance 2 drew $mid, expected between $coarsest and $finest"
"$AMGSPLAT" imgdiff "$T/c0.png" "$T/c2.png" --json >"$T/diff.json"
python3 -c "
import json, sys
d = json.load(open(sys.argv[1]))
assert d['ssim'] > 0.9, d" "$T/diff.json" || fail "the mixed cut is far from full detail: $(cat "$T/diff.json")"

# one level draws as it is; the prim renderer stays the default
"$AMGSPLAT" render "$T/one.dps" --renderer cut -o "$T/one.png" --size 64x64 -q
check "$T/one.png" "px(32, 10)[:3] != (255, 255, 255)"
"$AMGSPLAT" render "$T/t.dps" -o "$T/p.png" --size 64x64 --json >"$T/p.json"
grep -F '"renderer": "prim"' "$T/p.json" >/dev/null || fail "default renderer: $(cat "$T/p.json")"

# refused: a point renderer for a .dps, the cut for points
expect_fail 2 "--renderer cut" "$AMGSPLAT" render "$T/t.dps" --renderer disc -o "$T/x.png"
expect_fail 2 "unknown renderer 'cut'" "$AMGSPLAT" render "$T/t.ply" --renderer cut -o "$T/x.png"
[[ ! -e "$T/x.png" ]] || fail "a refused render wrote its output"
echo ok
