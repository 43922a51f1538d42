#!/usr/bin/env bash
# Mutation run (issue #31 "Done when"): N mutated mesh and point inputs (default 2400), made with a
# fixed seed from small valid files of every format the tool reads (OBJ, OFF, ASCII and binary STL,
# PLY points and mesh, xyz, LAS, glTF, GLB, Collada, 3DS), each given to 'info' and to 'sample'
# (meshes) or 'convert' to PLY (points). Counts: runs ended by a signal, timeouts (20 s), peak
# resident memory over 500 MB, and successful outputs that 'amgsplat info' refuses. Benchmark-style:
# it reports, it does not judge (tests/cli/hostile_*.sh are the tests).
#
#   bench/mutate_inputs.sh AMGSPLAT [N=2400] [SEED=31] [JOBS=2] [DIR=mktemp]
set -euo pipefail
bin=$(realpath "${1:?amgsplat binary}"); n=${2:-2400}; seed=${3:-31}; jobs=${4:-2}
dir=${5:-$(mktemp -d)}
here=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$dir/in" "$dir/out" "$dir/log"
cd "$dir"
echo "load: $(uptime)"
# ---- seeds: one small valid file per format ----
"$bin" synth octahedron --points 300 -o seed_points.ply -q
"$bin" convert seed_points.ply seed_points.xyz -q
"$bin" convert seed_points.ply seed_points.las -q
python3 "$here/tests/data/bad/assimp/make_cases.py" "$dir" >/dev/null
mv ok_tri.gltf seed_tri.gltf; mv ok_tri.glb seed_tri.glb; mv ok_tri.dae seed_tri.dae; mv ok_tri.3ds seed_tri.3ds
mv ok_sparse.gltf seed_sparse.gltf
rm -f dae_* gltf_* glb_* 3ds_*
python3 - <<'PY'
import struct
quad_v = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0.5, 0.5, 1)]
faces = [(0, 1, 2), (0, 2, 3), (0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4)]
with open('seed_mesh.obj', 'w') as f:
    f.write('# pyramid\n' + ''.join('v %g %g %g\n' % v for v in quad_v) + 'vt 0 0\nvt 1 0\nvt 1 1\n'
            + ''.join('f %d/1 %d/2 %d/3\n' % (a + 1, b + 1, c + 1) for a, b, c in faces))
with open('seed_mesh.off', 'w') as f:
    f.write('OFF\n%d %d 0\n' % (len(quad_v), len(faces)) + ''.join('%g %g %g\n' % v for v in quad_v)
            + ''.join('3 %d %d %d\n' % t for t in faces))
with open('seed_ascii.stl', 'w') as f:
    f.write('solid p\n')
    for t in faces:
        f.write('facet normal 0 0 1\nouter loop\n' + ''.join('vertex %g %g %g\n' % quad_v[i] for i in t)
                + 'endloop\nendfacet\n')
    f.write('endsolid p\n')
with open('seed_binary.stl', 'wb') as f:
    f.write(b'\0' * 80 + struct.pack('<I', len(faces)))
    for t in faces:
        f.write(struct.pack('<3f', 0, 0, 1) + b''.join(struct.pack('<3f', *quad_v[i]) for i in t) + b'\0\0')
with open('seed_mesh.ply', 'wb') as f:
    f.write(b'ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n'
            b'property float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n'
            % (len(quad_v), len(faces)))
    f.write(b''.join(struct.pack('<3f', *v) for v in quad_v))
    f.write(b''.join(struct.pack('<B3i', 3, *t) for t in faces))
PY
# ---- mutations, fixed seed ----
python3 - "$n" "$seed" <<'PY'
import glob, os, random, struct, sys
n, seed = int(sys.argv[1]), int(sys.argv[2])
rng = random.Random(seed)
seeds = sorted(glob.glob('seed_*'))
data = {s: open(s, 'rb').read() for s in seeds}
specials = [b'-1', b'0', b'4294967295', b'999999999999', b'1e38', b'-1e38', b'nan', b'inf', b'1e308', b'']
def mutate(b):
    b = bytearray(b)
    kind = rng.randrange(7)
    if kind == 0 and len(b) > 1:                    # truncation
        del b[rng.randrange(1, len(b)):]
    elif kind == 1:                                 # bit flips
        for _ in range(rng.randint(1, 8)):
            i = rng.randrange(len(b)); b[i] ^= 1 << rng.randrange(8)
    elif kind == 2:                                 # a number in the text replaced by a lie or a non-number
        digits = [i for i in range(len(b)) if chr(b[i]).isdigit()]
        if digits:
            i = rng.choice(digits); j = i
            while j < len(b) and (chr(b[j]).isdigit() or b[j] in b'.-e'):
                j += 1
            b[i:j] = rng.choice(specials)
    elif kind == 3 and len(b) >= 8:                 # a binary field replaced: u32 / f32 / f64 lies
        i = rng.randrange(len(b) - 8)
        v = rng.choice([struct.pack('<I', 0xFFFFFFFF), struct.pack('<I', 0x7FFFFFFF), struct.pack('<f', float('nan')),
                        struct.pack('<f', 3e38), struct.pack('<d', float('inf')), struct.pack('<d', 1e300)])
        b[i:i + len(v)] = v
    elif kind == 4:                                 # a token or a line deleted
        i = rng.randrange(len(b)); j = min(len(b), i + rng.randint(1, 40))
        del b[i:j]
    elif kind == 5:                                 # a slice duplicated
        i = rng.randrange(len(b)); j = min(len(b), i + rng.randint(1, 200))
        b[i:i] = b[i:j]
    else:                                           # random bytes over a slice
        i = rng.randrange(len(b))
        for k in range(i, min(len(b), i + rng.randint(1, 16))):
            b[k] = rng.randrange(256)
    return bytes(b)
for k in range(n):
    s = seeds[k % len(seeds)]
    ext = s.rsplit('.', 1)[1]
    kind = 'points' if s.startswith('seed_points') else 'mesh'
    with open('in/%05d_%s.%s' % (k, kind, ext), 'wb') as f:
        f.write(mutate(data[s]))
PY
echo "$(ls in | wc -l) inputs from $(ls seed_* | wc -l) seeds (seed $seed) in $dir/in"
# ---- runs ----
run_one() {
  local f=$1 bin=$2 dir=$3
  local b out st info_st kb
  b=$(basename "$f")
  case $b in *_points.*) out=$dir/out/$b.ply; cmd=(convert "$f" "$out" -q) ;; *) out=$dir/out/$b.ply; cmd=(sample "$f" -o "$out" --points 200 -q) ;; esac
  for c in info main; do
    local args
    if [[ $c == info ]]; then args=(info "$f"); else args=("${cmd[@]}"); fi
    st=0
    /usr/bin/time -f '%M' -o "$dir/log/$b.$c.rss" timeout 20 "$bin" "${args[@]}" >"$dir/log/$b.$c.out" 2>"$dir/log/$b.$c.err" || st=$?
    kb=$(tail -n 1 "$dir/log/$b.$c.rss" | grep -Eo '^[0-9]+$' || echo 0)
    local verdict=ok
    if ((st == 124)); then verdict=timeout
    elif ((st > 128)) || grep -q 'Command terminated by signal' "$dir/log/$b.$c.rss"; then verdict=signal
    elif ((st != 0 && st != 1 && st != 2)); then verdict=status$st
    elif ((st != 0)) && ! grep -qF "$f" "$dir/log/$b.$c.err" && ! grep -qF -- "$(basename "$out")" "$dir/log/$b.$c.err"; then verdict=unnamed
    fi
    if [[ $c == main && $st == 0 ]]; then
      info_st=0
      timeout 20 "$bin" info "$out" >/dev/null 2>"$dir/log/$b.reinfo.err" || info_st=$?
      ((info_st == 0)) || verdict=output_refused
    fi
    ((kb > 500000)) && verdict="$verdict+rss"
    echo "$b $c $st $kb $verdict"
  done
}
export -f run_one
t0=$(date +%s)
ls in/* | xargs -P "$jobs" -I{} bash -c 'run_one "$@"' _ {} "$bin" "$dir" >results.txt
t1=$(date +%s)
echo "runs: $(wc -l <results.txt) in $((t1 - t0)) s with $jobs jobs"
awk '{v[$5]++; if ($3 == 0) ok[$2]++} END {for (k in v) printf "  %-16s %d\n", k, v[k]; printf "  succeeded: info %d, sample/convert %d\n", ok["info"], ok["main"]}' results.txt | sort
for bad in signal timeout output_refused unnamed rss; do
  grep -E " [a-z_0-9]*$bad" results.txt | head -5 | sed "s/^/  e.g. /" || true
done
echo "signals $(grep -c ' signal' results.txt || true), timeouts $(grep -c ' timeout' results.txt || true)," \
  "outputs info refuses $(grep -c 'output_refused' results.txt || true), over 500 MB $(grep -c '+rss' results.txt || true)," \
  "errors not naming the file $(grep -c ' unnamed' results.txt || true)"
