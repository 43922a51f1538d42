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

# thesis appendix C "one picked domain only": g draws the first primitive alone, each further g the
# next. Which primitives face a view depends on the numbering of the domains (the Morton numbering of
# src/amg/morton.c puts the first ones in one corner), so picks 1..4 are drawn from two opposite views
# and two of them must show a visible part smaller than half the whole, and differ.
"$A" decompose "$T/s.ply" -o "$T/s.amg" -q
"$A" build "$T/s.amg" --primitives 30 -o "$T/s.dps" -q >/dev/null
px() { "$A" imgdiff "$1" "$2" --background 255,255,255 | awk '/^silhouette B/ { print $(NF-1) }'; }
seen=() counts=()
for view in 30,20 210,-20; do
  W=(--size 96x96 --view "$view" -q)
  "$A" view "$T/s.dps" --frames 1 --screenshot "$T/all.png" "${W[@]}"
  all=$(px "$T/all.png" "$T/all.png")
  for k in 1 2 3 4; do
    keys=$(printf 'g%.0s' $(seq "$k"))
    "$A" view "$T/s.dps" --frames $((k + 1)) --keys "$keys" --screenshot "$T/pick$k.$view.png" "${W[@]}"
    n=$(px "$T/all.png" "$T/pick$k.$view.png")
    counts+=("$view:$k:$n/$all")
    (( n > 0 && n * 2 < all )) && seen+=("$k.$view")
  done
done
((${#seen[@]} >= 2)) || fail "picked domain: pixels ${counts[*]}"
cmp -s "$T/pick${seen[0]}.png" "$T/pick${seen[1]}.png" && fail "g drew the same domain for picks ${seen[0]} and ${seen[1]}"
exit 0
