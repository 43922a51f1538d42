# The renderer options render, view and eval share (src/cli/renderer_options.c, issue 26): one
# declaration, one check, every old spelling accepted by every command that takes the option
# (--tau = --tolerance, --color = --color-by), both spellings at once refused.
source "$(dirname "$0")/common.sh"
A=$AMGSPLAT
"$A" synth sphere -n 500 -o "$T/s.ply" -q
# the value given under either name reaches the renderer
for name in tolerance tau; do
  "$A" render "$T/s.ply" -o "$T/$name.png" --size 32x32 --renderer splat --$name 3 --json >"$T/$name.json"
  python3 -c "import json,sys; d=json.load(open(sys.argv[1])); assert d['tolerance'] == 3, d" "$T/$name.json" \
    || fail "render --$name 3: $(cat "$T/$name.json")"
done
cmp -s "$T/tolerance.png" "$T/tau.png" || fail "render --tau 3 and --tolerance 3 differ"
# the same checks under each name, in each command, naming the spelling given
expect_fail 2 "--tau expects pixels in 0..1e6, got -1" "$A" render "$T/s.ply" -o "$T/x.png" --tau -1
expect_fail 2 "--tolerance expects pixels in 0..1e6, got -1" "$A" view "$T/s.ply" --tolerance -1
expect_fail 2 "--tolerance and --tau are the same option; give one" "$A" render "$T/s.ply" -o "$T/x.png" --tau 1 --tolerance 2
expect_fail 2 "--tolerance and --tau are the same option; give one" "$A" view "$T/s.ply" --tau 1 --tolerance 2
expect_fail 2 "--color-by and --color are the same option; give one" "$A" view "$T/s.ply" --color input --color-by input
expect_fail 2 "--color expects classifier, domains, strict or input" "$A" render "$T/s.ply" -o "$T/x.png" --color rainbow
expect_fail 2 "--color-by expects classifier, domains, strict or input" "$A" view "$T/s.ply" --color-by rainbow
expect_fail 2 "--color needs an .amg input" "$A" render "$T/s.ply" -o "$T/x.png" --color classifier
for cmd in render view; do
  out=(); [[ $cmd == render ]] && out=(-o "$T/x.png")
  expect_fail 2 "--depth-limit expects 0..64, got 65" "$A" $cmd "$T/s.ply" "${out[@]}" --depth-limit 65
  expect_fail 2 "--frame-ms expects milliseconds in 0..1e6" "$A" $cmd "$T/s.ply" "${out[@]}" --frame-ms -1
  expect_fail 2 "--method: " "$A" $cmd "$T/s.ply" "${out[@]}" --method blob
done
# eval takes the crease angle and the texture, not the options it sets per representation
expect_fail 2 "--crease-angle expects degrees in (0, 180) or 'off', got 'soft'" "$A" eval octahedron --crease-angle soft
expect_fail 2 "--crease-angle expects degrees in (0, 90) or 'off', got '120'" "$A" eval octahedron --crease-angle 120
expect_fail 2 "unknown option '--tau'" "$A" eval octahedron --tau 1
# each command's help lists the shared options once, aliases included
"$A" render -h >"$T/h"
for o in --renderer --tolerance --tau --budget --color-by --color --level --method --alpha-ref --crease-angle \
         --hybrid --cull-backfaces --depth-limit --frame-ms --unlit --texture; do
  [[ $(grep -c -- "^ *$o " "$T/h") == 1 ]] || fail "render -h lists $o $(grep -c -- "^ *$o " "$T/h") times"
done
echo "renderer_options: ok"
