#!/usr/bin/env bash
# Seed options of view (issue 17, docs/seeds.md): --preset picks the seed's renderer, seed 004's
# normal-cone culling (3.2.2) and depth limit (3.2.5) cut the splats drawn; scripted frames in a real
# window (Xvfb + Mesa llvmpipe), as tests/cli/view.sh, which explains the display requirement.
if [[ -z "${ASP_VIEW_UNDER_XVFB:-}" ]] && command -v xvfb-run >/dev/null; then
  ASP_VIEW_UNDER_XVFB=1 exec xvfb-run -a -s "-screen 0 1024x768x24" bash "$0" "$@"
fi
source "$(dirname "$0")/common.sh"
[[ -n "${DISPLAY:-}" ]] || fail "no xvfb-run and no DISPLAY: install xvfb (scripts/bootstrap.sh) to run the viewer tests"
A="$AMGSPLAT"
jget() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(eval(sys.argv[2]))" "$@"; }

"$A" synth sphere --points 6000 -o "$T/s.ply" -q
V=(--frames 2 --size 96x96 --view 0,0 --json -q)
"$A" view "$T/s.ply" --preset pajarola "${V[@]}" >"$T/p.json"
[[ $(jget "$T/p.json" "d['renderer']") == "splat" ]] || fail "pajarola view: $(cat "$T/p.json")"
"$A" view "$T/s.ply" --preset schwarz "${V[@]}" >"$T/q.json"
[[ $(jget "$T/q.json" "d['renderer']") == "square" ]] || fail "schwarz view: $(cat "$T/q.json")"
"$A" view "$T/s.ply" --renderer splat "${V[@]}" >"$T/a.json"
"$A" view "$T/s.ply" --renderer splat --cull-backfaces "${V[@]}" >"$T/b.json"
"$A" view "$T/s.ply" --renderer splat --depth-limit 3 "${V[@]}" >"$T/c.json"
python3 - "$T" <<'PY' || fail "view culling / depth limit: $(cat "$T"/[abc].json)"
import json, sys
n = [json.load(open("%s/%s.json" % (sys.argv[1], x)))["count"] for x in "abc"]
assert n[0] == 6000 and n[1] < 0.7 * n[0] and n[2] <= 8 ** 3, n
PY
expect_fail 2 "--depth-limit expects 0..64" "$A" view "$T/s.ply" --depth-limit 65

# thesis appendix C "one picked domain only": g draws the first primitive alone, a second g the next
"$A" decompose "$T/s.ply" -o "$T/s.amg" -q
"$A" build "$T/s.amg" --primitives 30 -o "$T/s.dps" -q >/dev/null
W=(--size 96x96 --view 30,20 -q)
"$A" view "$T/s.dps" --frames 1 --screenshot "$T/all.png" "${W[@]}"
"$A" view "$T/s.dps" --frames 2 --keys g --screenshot "$T/one.png" "${W[@]}"
"$A" view "$T/s.dps" --frames 3 --keys gg --screenshot "$T/two.png" "${W[@]}"
px() { "$A" imgdiff "$1" "$2" --background 255,255,255 | awk '/^silhouette B/ { print $(NF-1) }'; }
all=$(px "$T/all.png" "$T/all.png") one=$(px "$T/all.png" "$T/one.png") two=$(px "$T/all.png" "$T/two.png")
(( one > 0 && one * 2 < all && two > 0 && two * 2 < all )) || fail "picked domain: $one and $two of $all pixels"
cmp -s "$T/one.png" "$T/two.png" && fail "g twice drew the same domain"
exit 0
