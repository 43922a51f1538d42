# The out-of-core hierarchy (issue 28): synth terrain streams a deterministic point file; convert
# IN -o OUT.hier with a small --memory really chunks it (several chunk files), keeps every point
# once and writes the same bytes for any thread count; info reads the streamed header; render
# loads only a view's cut (fewer points far away, all of them at a fine tolerance, within a
# --memory budget) and matches the same points drawn whole (amgsplat render IN.ply) at SSIM >=
# 0.95 in close-ups; damaged files and inputs it cannot stream fail with messages.
source "$(dirname "$0")/common.sh"
A=$AMGSPLAT
jget() { python3 -c 'import json, sys; d = json.load(open(sys.argv[1])); print(d[sys.argv[2]])' "$@"; }
ssim() { "$A" imgdiff --json "$1" "$2" | python3 -c 'import json, sys; print(json.load(sys.stdin)["ssim"])'; }
at_least() {
  python3 -c 'import sys; sys.exit(0 if float(sys.argv[1]) >= float(sys.argv[2]) else 1)' "$1" "$2" ||
    fail "$3: $1 < $2"
}

# the generator: equal seeds give equal files, another seed another file
"$A" synth terrain --points 200000 -o "$T/a.ply" -q
"$A" synth terrain --points 200000 -o "$T/b.ply" -q
cmp -s "$T/a.ply" "$T/b.ply" || fail "synth terrain is not deterministic"
"$A" synth terrain --points 200000 --seed 3 -o "$T/c.ply" -q
cmp -s "$T/a.ply" "$T/c.ply" && fail "synth terrain ignores --seed"
expect_fail 2 "OUT.ply" "$A" synth terrain --points 10 -o "$T/t.las"

"$A" synth terrain --points 2000000 -o "$T/t.ply" --json > "$T/synth.json"
[[ $(jget "$T/synth.json" points) == 2000000 ]] || fail "synth wrote $(jget "$T/synth.json" points) points"
[[ $(stat -c %s "$T/t.ply") -gt 30000000 ]] || fail "t.ply is smaller than 2M x 15 bytes"

# convert with a 64 MiB budget: chunks, every point once, same bytes with 1 and 2 threads
"$A" convert "$T/t.ply" -o "$T/t.hier" --memory 64M --node-points 8192 --json > "$T/conv.json"
[[ $(jget "$T/conv.json" points) == 2000000 ]] || fail "convert kept $(jget "$T/conv.json" points) points"
(($(jget "$T/conv.json" chunks) >= 4)) || fail "64M did not chunk: $(jget "$T/conv.json" chunks) chunks"
(($(jget "$T/conv.json" nodes) > 100)) || fail "only $(jget "$T/conv.json" nodes) nodes"
"$A" convert "$T/t.ply" -o "$T/t1.hier" --memory 64M --node-points 8192 --threads 1 -q
cmp -s "$T/t.hier" "$T/t1.hier" || fail "the streamed .hier depends on the thread count"
ls "$T"/*.chunks.* >/dev/null 2>&1 && fail "chunk files left behind"
# record sizes: a header, 16 bytes a point and 56 a node
nodes=$(jget "$T/conv.json" nodes)
[[ $(stat -c %s "$T/t.hier") -eq $((160 + 16 * 2000000 + 56 * nodes)) ]] || fail "t.hier has an unexpected size"

"$A" info "$T/t.hier" --json > "$T/info.json"
[[ $(jget "$T/info.json" layout) == streamed && $(jget "$T/info.json" points) == 2000000 ]] ||
  fail "info: $(cat "$T/info.json")"

# the frame's box is recorded (issue 29's framing of flat sites): the points' extent plus a disc
"$A" info "$T/t.ply" --json > "$T/pinfo.json"
python3 - "$T/info.json" "$T/pinfo.json" <<'EOF' || fail "the streamed file's frame box: $(cat "$T/info.json")"
import json, sys
h, p = (json.load(open(f)) for f in sys.argv[1:])
box, r = h["frame"]["box"], h["frame"]["radius"]
for k in range(3):
    ext = p["bbox_max"][k] - p["bbox_min"][k]
    assert ext <= box[k] <= ext + 0.02 * r, (k, ext, box, r)
EOF

# render: far away a coarse cut, at a fine tolerance every point; the same frame as the points
"$A" render "$T/t.hier" -o "$T/far.png" --size 128x128 --up z --view 30,40 --json > "$T/far.json"
far=$(jget "$T/far.json" points)
((far > 1000 && far < 2000000)) || fail "the far cut loaded $far points, expected a part of 2000000"
"$A" render "$T/t.hier" -o "$T/all.png" --size 128x128 --up z --view 30,40 --tolerance 0.001 --json > "$T/all.json"
[[ $(jget "$T/all.json" points) == 2000000 ]] || fail "a fine tolerance loaded $(jget "$T/all.json" points) points"
"$A" render "$T/t.ply" -o "$T/ply.png" --size 128x128 --up z --view 30,40 --json > "$T/ply.json"
python3 - "$T/all.json" "$T/ply.json" <<'EOF' || fail "the streamed file is framed unlike its points"
import json, sys
a, b = (json.load(open(p))["frame"] for p in sys.argv[1:])
sys.exit(0 if all(abs(x - y) <= 1e-3 * b[3] for x, y in zip(a, b)) else 1)
EOF
check "$T/far.png" "fg > 0.2"

# close-ups against the whole point set drawn from memory (discs both)
for v in 0,90,0.2 30,60,0.3; do
  "$A" render "$T/t.hier" -o "$T/s.png" --size 256x256 --up z --view $v -q
  "$A" render "$T/t.ply" -o "$T/p.png" --size 256x256 --up z --view $v -q
  at_least "$(ssim "$T/s.png" "$T/p.png")" 0.95 "close-up $v: streamed vs in-memory SSIM"
done

# a small --memory keeps the cut within its budget (64 bytes a point), coarse first: still covered
"$A" render "$T/t.hier" -o "$T/small.png" --size 128x128 --up z --view 30,60,0.3 --memory 4M --json > "$T/small.json"
(($(jget "$T/small.json" points) <= 65536)) || fail "--memory 4M loaded $(jget "$T/small.json" points) points"
check "$T/small.png" "fg > 0.9"
expect_fail 2 "--memory" "$A" render "$T/t.ply" -o "$T/x.png" --memory 1G
expect_fail 2 "--memory" "$A" convert "$T/t.ply" -o "$T/x.hier" --memory lots

# damage: truncation, a changed node table byte, a streamed file where the in-memory layout is read
head -c 1000000 "$T/t.hier" > "$T/cut.hier"
expect_fail 1 "cut.hier" "$A" info "$T/cut.hier"
cp "$T/t.hier" "$T/bad.hier"
size=$(stat -c %s "$T/bad.hier")
printf '\x7f' | dd of="$T/bad.hier" bs=1 seek=$((size - 30)) conv=notrunc 2>/dev/null
expect_fail 1 "checksum" "$A" render "$T/bad.hier" -o "$T/x.png" --size 64x64
expect_fail 1 "streamed hierarchy" "$A" export "$T/t.hier" -o "$T/x.glb"
# inputs the batched reader does not take
"$A" convert "$T/a.ply" "$T/a.xyz" -q
expect_fail 1 "convert it first" "$A" convert "$T/a.xyz" -o "$T/x.hier"
"$A" convert "$T/a.ply" "$T/asc.ply" --ascii -q
expect_fail 1 "binary PLY" "$A" convert "$T/asc.ply" -o "$T/x.hier"
# LAS streams too: the same points
"$A" convert "$T/a.ply" "$T/a.las" -q
"$A" convert "$T/a.las" -o "$T/las.hier" --json > "$T/las.json"
[[ $(jget "$T/las.json" points) == 200000 ]] || fail "LAS: $(jget "$T/las.json" points) points"
# the streamed file keeps the source's up axis (issue 29): a LAS is z-up, so render needs no --up
# (the same picture as --up z, another from --up y), a PLY stays y-up
"$A" render "$T/las.hier" -o "$T/las_default.png" --size 96x96 --view 30,40 -q
"$A" render "$T/las.hier" -o "$T/las_z.png" --size 96x96 --view 30,40 --up z -q
"$A" render "$T/las.hier" -o "$T/las_y.png" --size 96x96 --view 30,40 --up y -q
at_least "$(ssim "$T/las_default.png" "$T/las_z.png")" 0.999 "streamed LAS drawn by its own up axis (z)"
s=$(ssim "$T/las_default.png" "$T/las_y.png")
python3 -c "import sys; sys.exit(0 if float(sys.argv[1]) < 0.9 else 1)" "$s" || fail "streamed LAS: --up y draws as z (SSIM $s)"
exit 0
