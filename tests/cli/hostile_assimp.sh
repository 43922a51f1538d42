# Hostile meshes for the readers inside assimp (issue #31): Collada, glTF/GLB and 3DS files that
# crashed assimp (SIGSEGV), made it allocate gigabytes or read out of bounds. Each must fail at
# once with exit 1 or 2 and a message naming the file, under 500 MB resident, in info and sample;
# the valid files beside them load. The committed cases are what make_cases.py makes.
source "$(dirname "$0")/common.sh"
A=$AMGSPLAT
D=$ASP_TEST_SRC/data/bad/assimp

# the corpus is the generator's output, byte for byte
mkdir -p "$T/made"
python3 "$D/make_cases.py" "$T/made"
for f in "$T"/made/*; do
  cmp -s "$f" "$D/$(basename "$f")" || fail "$(basename "$f") differs from what make_cases.py makes"
done

# refused F: exit 1 or 2, F named on stderr, no signal, peak resident memory under 500 MB
refused() {
  local f=$1; shift
  local st=0
  /usr/bin/time -f '%M' -o "$T/rss" timeout 60 "$A" "$@" >"$T/out" 2>"$T/err" || st=$?
  ((st == 1 || st == 2)) || fail "'$*' exited $st, expected 1 or 2; stderr: $(cat "$T/err")"
  grep -qF "'$f'" "$T/err" || fail "'$*': stderr does not name '$f': $(cat "$T/err")"
  local kb
  kb=$(tail -n 1 "$T/rss")
  ((kb < 500000)) || fail "'$*' reached $kb kB resident"
}

n=0
for f in "$D"/dae_* "$D"/gltf_* "$D"/glb_* "$D"/3ds_*; do
  refused "$f" info "$f"
  refused "$f" sample "$f" -o "$T/o.ply" --points 100 -q
  n=$((n + 1))
done
((n >= 19)) || fail "only $n cases"
# the lies are named, with their numbers
expect_fail 1 "<float_array> count=\"-1\" is not a count" "$A" info "$D/dae_count_negative.dae"
expect_fail 1 "<float_array> count=\"9\" but it holds 8 values" "$A" info "$D/dae_token_deleted.dae"
expect_fail 1 "GLB chunk 0 declares 4294967295 bytes, but 568 follow" "$A" info "$D/glb_json_length.glb"
expect_fail 1 "its GLB header declares 4294967295 bytes, but the file has 588" "$A" info "$D/glb_header_length.glb"
expect_fail 1 "accessor 0: sparse index 0 is 40000, past its 3 elements" "$A" info "$D/gltf_sparse_past.gltf"
expect_fail 1 "3DS vertex list of 5000 entries does not fit its chunk of 38 bytes" "$A" info "$D/3ds_vertex_count.3ds"

# the valid files of each format load, through the reader process, with their one triangle
for f in "$D"/ok_*; do
  expect_exit 0 "$A" sample "$f" -o "$T/o.ply" --points 100 -q
  expect_exit 0 "$A" info "$f"
  grep -E '^faces +1 \(triangles\)$' "$T/out" >/dev/null || fail "info $f: $(cat "$T/out")"
done
