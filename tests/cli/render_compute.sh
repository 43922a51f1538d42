# amgsplat render --renderer compute (issue 28): the compute-shader rasteriser against the raster
# renderers at the same views by SSIM (amgsplat imgdiff): opaque against disc (discs of a cloud
# with normals and radii) and opaque splat (the hierarchy's k-neighbourhood ellipses of a cloud
# without radii), blended against splat (seed 001 5.3-5.4); a close-up whose splats cover hundreds
# of pixels (the big-splat list), an odd non-square size, a scene of instances (the renderer drawn
# once per instance), the atomic path in --json, and input it cannot draw.
source "$(dirname "$0")/common.sh"
A=$AMGSPLAT
ssim() { "$A" imgdiff --json "$1" "$2" | python3 -c 'import json, sys; print(json.load(sys.stdin)["ssim"])'; }
# at_least IMG_A IMG_B MIN WHAT
at_least() {
  local s
  s=$(ssim "$1" "$2")
  python3 -c 'import sys; sys.exit(0 if float(sys.argv[1]) >= float(sys.argv[2]) else 1)' "$s" "$3" ||
    fail "$4: SSIM $s < $3"
}
"$A" synth torus -o "$T/torus.ply" -n 50000 -q
"$A" synth torus -o "$T/torus.xyz" -n 50000 -q # normals and colours, no radii: kNN ellipses
"$A" synth torus -o "$T/t5k.ply" -n 5000 -q

r() { "$A" render "$1" -o "$2" --size "${SIZE:-256x256}" -q "${@:3}"; }
r "$T/torus.ply" "$T/disc.png"
r "$T/torus.ply" "$T/cop.png" --renderer compute --opaque
r "$T/torus.ply" "$T/splat.png" --renderer splat
r "$T/torus.ply" "$T/cbl.png" --renderer compute
check "$T/cop.png" "fg > 0.2"
check "$T/cbl.png" "fg > 0.2"
at_least "$T/disc.png" "$T/cop.png" 0.95 "opaque compute vs disc"
at_least "$T/splat.png" "$T/cbl.png" 0.95 "blended compute vs splat"

r "$T/torus.xyz" "$T/splat_op_knn.png" --renderer splat --opaque
r "$T/torus.xyz" "$T/cop_knn.png" --renderer compute --opaque
r "$T/torus.xyz" "$T/splat_knn.png" --renderer splat
r "$T/torus.xyz" "$T/cbl_knn.png" --renderer compute
at_least "$T/splat_op_knn.png" "$T/cop_knn.png" 0.95 "opaque compute vs opaque splat (kNN ellipses)"
at_least "$T/splat_knn.png" "$T/cbl_knn.png" 0.95 "blended compute vs splat (kNN ellipses)"

# close up: 5000 splats of tens of pixels across go through the one-workgroup-per-splat list
r "$T/t5k.ply" "$T/near_splat.png" --renderer splat --view 30,60,0.9
r "$T/t5k.ply" "$T/near_cbl.png" --renderer compute --view 30,60,0.9
r "$T/t5k.ply" "$T/near_disc.png" --view 30,60,0.9
r "$T/t5k.ply" "$T/near_cop.png" --renderer compute --opaque --view 30,60,0.9
check "$T/near_cbl.png" "fg > 0.5"
at_least "$T/near_splat.png" "$T/near_cbl.png" 0.95 "close-up blended compute vs splat"
at_least "$T/near_disc.png" "$T/near_cop.png" 0.95 "close-up opaque compute vs disc"

# odd, non-square size: pixel rows of the storage framebuffer are the image's
SIZE=97x61 r "$T/torus.ply" "$T/odd_splat.png" --renderer splat
SIZE=97x61 r "$T/torus.ply" "$T/odd_cbl.png" --renderer compute
check "$T/odd_cbl.png" "w == 97 and h == 61 and fg > 0.2"
at_least "$T/odd_splat.png" "$T/odd_cbl.png" 0.95 "97x61 blended compute vs splat"

# a scene: each instance is one draw whose resolve composes by depth with the others
"$A" synth sphere -o "$T/sphere.ply" -n 4000 -q
"$A" scene field "$T/sphere.ply" --instances 20 --seed 3 -o "$T/field.json" -q
r "$T/field.json" "$T/scene_disc.png"
r "$T/field.json" "$T/scene_cop.png" --renderer compute --opaque
at_least "$T/scene_disc.png" "$T/scene_cop.png" 0.95 "scene of 20 instances, opaque compute vs disc"

# --json says which atomics drew: 64-bit where GL_NV_shader_atomic_int64 exists, else 32-bit
"$A" render "$T/torus.ply" -o "$T/j.png" --size 64x64 --renderer compute --opaque --json >"$T/j"
python3 -c 'import json, sys; d = json.load(open(sys.argv[1])); assert d["renderer"] == "compute" and d["compute_path"] in ("opaque-atomic32", "opaque-atomic64"), d' "$T/j" ||
  fail "opaque path in --json: $(cat "$T/j")"
"$A" render "$T/torus.ply" -o "$T/j.png" --size 64x64 --renderer compute --json >"$T/j"
python3 -c 'import json, sys; d = json.load(open(sys.argv[1])); assert d["compute_path"] == "blend-atomic32", d' "$T/j" ||
  fail "blended path in --json: $(cat "$T/j")"
"$A" render "$T/torus.ply" -o "$T/j.png" --size 64x64 --json >"$T/j"
python3 -c 'import json, sys; d = json.load(open(sys.argv[1])); assert "compute_path" not in d, d' "$T/j" ||
  fail "disc has no compute_path: $(cat "$T/j")"

# what it does not draw is refused, not ignored: crease clip planes
expect_fail 2 "the compute renderer does not clip" "$A" render "$T/torus.ply" -o "$T/x.png" --renderer compute --crease-angle 30
