# export --tiles (issue 32): point sets and hierarchies as 3D Tiles 1.1 tilesets. No browser needed
# (web_tiles.sh has the page, the validator and Cesium).
#  - a point file takes the bounded-memory route (converted to a temporary streamed .hier, which is
#    removed, then one tile a node): refine ADD, every point in exactly one tile (the GLBs' counts sum
#    to the input's), each tile's box holding its GLB's points (accessor bounds through the node
#    transform, turned z-up) and its children's boxes, geometricError = node spacing, never growing
#    downwards and 0 at the leaves, a disc radius in every tile's extras, no Gaussian splats,
#    identical output twice, a streamed .hier (amgsplat convert) giving the same tileset, and a
#    truncated streamed .hier refused with a message;
#  - an in-memory .hier (tools/seed_hier) keeps the REPLACE route: tileset.json's structure (asset
#    1.1, a root with children, refine REPLACE, boxes holding their children's, geometricError never
#    growing downwards and 0 exactly at the full-resolution leaves), every content URI a GLB on disk
#    and every GLB named once, the leaves' points summing to the input's (each point in exactly one
#    leaf), the root within the tile budget, the first frame's files (tileset.json + root) under 5%
#    of the bytes, identical output twice;
#  - the errors of bad options.
source "$(dirname "$0")/common.sh"
export PYTHONPATH="$(cd "$(dirname "$0")" && pwd)${PYTHONPATH:+:$PYTHONPATH}" # tileset_check.py

"$AMGSPLAT" synth torus -o "$T/torus.ply" --points 60000 -q

# ---- a point file: the streamed route (refine ADD) ----
"$AMGSPLAT" export "$T/torus.ply" -o "$T/add" --tiles --tile-points 2048 --json >"$T/add.json"
"$AMGSPLAT" export "$T/torus.ply" -o "$T/add2" --tiles --tile-points 2048 -q
cmp "$T/add/tileset.json" "$T/add2/tileset.json" || fail "two exports of the same points differ"
cmp "$T/add/tiles/0.glb" "$T/add2/tiles/0.glb" || fail "two exports of the same points differ (root GLB)"
ls "$T" | grep '\.convert-.*\.hier' >/dev/null && fail "the temporary streamed hierarchy was left: $(ls "$T")"
# a streamed .hier gives the same tileset
"$AMGSPLAT" convert "$T/torus.ply" -o "$T/torus_s.hier" --node-points 2048 -q
"$AMGSPLAT" export "$T/torus_s.hier" -o "$T/adds" --tiles -q
cmp "$T/add/tileset.json" "$T/adds/tileset.json" || fail "a streamed .hier and its point file tile differently"

python3 - "$T/add" "$T/add.json" 60000 <<'PY' || fail "streamed tileset structure"
import json, os, sys
from tileset_check import glb, walk, files_match, total_bytes
d, run, n_in = sys.argv[1], json.load(open(sys.argv[2])), int(sys.argv[3])
ts = json.load(open(os.path.join(d, 'tileset.json')))
assert ts['asset']['version'] == '1.1', ts['asset']
root = ts['root']
assert root['refine'] == 'ADD' and root.get('children'), 'root without ADD or children'
assert ts['geometricError'] > root['geometricError'] > 0, (ts['geometricError'], root['geometricError'])

tiles, total_points, leaf_points = 0, 0, 0
def visit(t, lo, hi, depth):
    global tiles, total_points, leaf_points
    tiles += 1
    e, uri = t['geometricError'], t['content']['uri']
    g = glb(os.path.join(d, uri))
    assert 'KHR_gaussian_splatting' not in json.dumps(g), f'{uri}: streamed tiles carry no Gaussians'
    mesh = g['meshes'][0]
    pr = mesh['primitives'][0]
    assert pr['mode'] == 0 and set(pr['attributes']) == {'POSITION', 'COLOR_0'}, (uri, pr['attributes'])
    assert mesh['extras']['amgsplat']['pointRadius'] > 0, (uri, mesh.get('extras'))
    acc = g['accessors'][pr['attributes']['POSITION']]
    n = acc['count']
    total_points += n
    # the points' y-up bounds through the node transform, then z-up as the box: (x, y, z) -> (x, -z, y)
    node = g['nodes'][0]
    tr, s = node.get('translation', [0, 0, 0]), node.get('scale', [1, 1, 1])[0]
    plo = [tr[k] + s * acc['min'][k] for k in range(3)]
    phi = [tr[k] + s * acc['max'][k] for k in range(3)]
    zlo, zhi = [plo[0], -phi[2], plo[1]], [phi[0], -plo[2], phi[1]]
    tol = s + 1e-6
    for k in range(3):
        assert lo[k] - tol <= zlo[k] and zhi[k] <= hi[k] + tol, f'{uri}: points outside the box, axis {k}'
    kids = t.get('children', [])
    if not kids:
        assert e == 0, f'leaf {uri} has error {e}'
        leaf_points += n
    else:
        assert e > 0, f'inner tile {uri} with error 0'
uris = walk(ts, visit)
files_match(d, uris)
assert total_points == n_in, f'tiles hold {total_points} points, input {n_in}: each point must be in one tile'
assert run['refine'] == 'ADD' and run['tiles'] == tiles and run['points'] == n_in and run['splats'] == n_in, run
assert run['leaf_points'] == leaf_points < n_in and run['largest_tile'] > 0 and not run['gaussian_splats'], run
total = total_bytes(d, uris)
assert total == run['bytes'], (total, run['bytes'])
a = ts['extras']['amgsplat']
assert a['points'] == n_in and a['refine'] == 'ADD' and a['frame']['radius'] > 0, a
print(f'streamed: {tiles} tiles, depth {run["depth"]}, {total} bytes ({total / n_in:.2f} a point); root error '
      f'{root["geometricError"]:.4g}, {leaf_points} points in leaves')
PY

# a truncated streamed .hier is refused with a message naming it, and leaves no tileset
size=$(stat -c %s "$T/torus_s.hier")
head -c $((size - 100)) "$T/torus_s.hier" >"$T/cut.hier"
expect_fail 1 "cut.hier" "$AMGSPLAT" export "$T/cut.hier" -o "$T/cut" --tiles
[[ ! -e "$T/cut/tileset.json" ]] || fail "a truncated .hier left a tileset"
expect_fail 2 "--tile-points" "$AMGSPLAT" export "$T/torus_s.hier" -o "$T/x" --tiles --tile-points 100
expect_fail 2 "64 to 1000000" "$AMGSPLAT" export "$T/torus.ply" -o "$T/x" --tiles --tile-points 10
expect_fail 2 "--memory" "$AMGSPLAT" export "$T/torus_s.hier" -o "$T/x" --tiles --memory 100M
expect_fail 2 "--memory needs --tiles" "$AMGSPLAT" export "$T/torus.ply" -o "$T/x.glb" --memory 100M
expect_fail 1 "64 MiB" "$AMGSPLAT" export "$T/torus.ply" -o "$T/x" --tiles --memory 1M
# --plain: float positions, nothing compressed
"$AMGSPLAT" export "$T/torus.ply" -o "$T/addplain" --tiles --tile-points 2048 --plain -q
grep -o '"KHR_mesh_quantization"\|"EXT_meshopt_compression"' "$T/addplain/tiles/0.glb" >/dev/null &&
  fail "--plain streamed tiles carry quantisation or compression"
: >"$T/file"
expect_fail 1 "cannot create directory" "$AMGSPLAT" export "$T/torus.ply" -o "$T/file" --tiles
ls "$T" | grep '\.convert-.*\.hier' >/dev/null && fail "a failed export left its temporary file"

# a .dps: one tile a level, the coarsest the root, each level's one child the next finer (REPLACE);
# errors fall to 0 at the finest, boxes hold the finer ones', each GLB is the level as export writes
# it (its primitive count), the root transform holds the frame centre
"$AMGSPLAT" build "$T/torus.ply" -o "$T/torus.dps" --level L-4..L -q || fail "build"
"$AMGSPLAT" export "$T/torus.dps" -o "$T/dps" --tiles --json >"$T/dps.json" || fail "export --tiles of a .dps"
"$AMGSPLAT" info "$T/torus.dps" --json >"$T/dps_info.json"
python3 - "$T/dps" "$T/dps.json" "$T/dps_info.json" <<'PY' || fail "the .dps tileset: $(cat "$T/dps.json")"
import json, os, sys
from tileset_check import glb, walk, files_match
d, run, info = sys.argv[1], json.load(open(sys.argv[2])), json.load(open(sys.argv[3]))
ts = json.load(open(os.path.join(d, 'tileset.json')))
levels = sorted(info['levels'], key=lambda l: -l['primitives'])  # finest first
chain, t = [], ts['root']
assert t['refine'] == 'REPLACE' and len(t['transform']) == 16, t.keys()
while True:
    chain.append(t)
    if 'children' not in t: break
    assert len(t['children']) == 1, 'a level has one finer level'
    t = t['children'][0]
assert len(chain) == len(levels) == run['tiles'] >= 3, (len(chain), len(levels), run)
errors = [c['geometricError'] for c in chain]
assert errors[-1] == 0 and all(a >= b for a, b in zip(errors, errors[1:])) and errors[0] > 0, errors
for coarse, fine in zip(chain, chain[1:]):
    a, b = coarse['boundingVolume']['box'], fine['boundingVolume']['box']
    for k in range(3):
        assert a[k] - a[3 + 4 * k] <= b[k] - b[3 + 4 * k] + 1e-9 and b[k] + b[3 + 4 * k] <= a[k] + a[3 + 4 * k] + 1e-9, (k, a, b)
counts = []
for c in chain:
    g = glb(os.path.join(d, c['content']['uri']))
    counts.append(g['nodes'][0]['extras']['amgsplat']['primitives'])
    assert 'translation' not in g['nodes'][0], 'the tileset transform holds the origin'
assert counts == [l['primitives'] for l in reversed(levels)], (counts, levels)
files_match(d, walk(ts, lambda t, lo, hi, depth: None))
assert run['refine'] == 'REPLACE' and run['primitives'] == sum(counts), run
print(f'.dps tileset: {len(chain)} levels, primitives {counts}, errors {[round(e, 4) for e in errors]}')
PY
node_ok=0; command -v node >/dev/null && [[ -d "${ASP_TEST_SRC:-$(dirname "$0")/..}/../web/node_modules/gltf-validator" ]] && node_ok=1
if ((node_ok)); then
  node "${ASP_TEST_SRC:-$(dirname "$0")/..}/../web/test/validate.mjs" "$T/dps/tiles/L.glb" || fail "gltf-validator rejects a .dps tile"
fi
expect_fail 2 "a .dps tileset holds every level" "$AMGSPLAT" export "$T/torus.dps" -o "$T/x" --tiles --level L
expect_fail 2 "the tiles of a .dps are its levels" "$AMGSPLAT" export "$T/torus.dps" -o "$T/x" --tiles --tile-points 100

# ---- an in-memory .hier: its elliptical splats, refine REPLACE ----
seed_hier="$(dirname "$AMGSPLAT")/seed_hier"
if [[ ! -x "$seed_hier" ]]; then
  asp_skipped+=("$seed_hier")
  echo "export_tiles: ok"
  exit 0
fi
"$seed_hier" "$T/torus.ply" "$T/torus.hier" || fail "seed_hier"
"$AMGSPLAT" export "$T/torus.hier" -o "$T/tiles" --tiles --tile-points 2048 --json >"$T/run.json"
"$AMGSPLAT" export "$T/torus.hier" -o "$T/again" --tiles --tile-points 2048 -q
cmp "$T/tiles/tileset.json" "$T/again/tileset.json" || fail "two exports of the same hierarchy differ"

python3 - "$T/tiles" "$T/run.json" 60000 2048 <<'PY' || fail "tileset structure"
import json, os, sys
from tileset_check import glb, walk, files_match, total_bytes
d, run, n_in, budget = sys.argv[1], json.load(open(sys.argv[2])), int(sys.argv[3]), int(sys.argv[4])
ts = json.load(open(os.path.join(d, 'tileset.json')))
assert ts['asset']['version'] == '1.1', ts['asset']
root = ts['root']
assert root['refine'] == 'REPLACE' and root.get('children'), 'root without REPLACE or children'
assert ts['geometricError'] > root['geometricError'] > 0, (ts['geometricError'], root['geometricError'])

def glb_points(path):  # POSITION count of the one points primitive
    g = glb(path)
    pr = g['meshes'][0]['primitives'][0]
    assert pr['mode'] == 0, path
    return g['accessors'][pr['attributes']['POSITION']]['count']

leaf_points, tiles = 0, 0
def visit(t, lo, hi, depth):
    global leaf_points, tiles
    tiles += 1
    e, uri = t['geometricError'], t['content']['uri']
    path = os.path.join(d, uri)
    assert os.path.isfile(path), f'content {uri} missing'
    n = glb_points(path)
    kids = t.get('children', [])
    if not kids:
        assert e == 0 or n <= 1, f'leaf {uri} has error {e}'
    if e == 0:
        assert not kids, f'{uri}: error 0 with children'
        leaf_points += n
    if depth == 0:
        assert n <= budget, f'root holds {n} splats, budget {budget}'
    for c in kids:
        assert c['geometricError'] < e or c['geometricError'] == 0, 'error does not fall'
uris = walk(ts, visit)
files_match(d, uris)
assert leaf_points == n_in, f'leaves hold {leaf_points} points, input {n_in}'
assert run['tiles'] == tiles and run['points'] == n_in and run['leaf_points'] == n_in, run
assert run['largest_tile'] <= 4 * budget, run
total = total_bytes(d, uris)
assert total == run['bytes'], (total, run['bytes'])
first = os.path.getsize(os.path.join(d, root['content']['uri'])) + os.path.getsize(os.path.join(d, 'tileset.json'))
assert first <= 0.05 * total, f'first frame needs {first} of {total} bytes'
a = ts['extras']['amgsplat']
assert a['points'] == n_in and a['frame']['radius'] > 0, a
print(f'{tiles} tiles, {run["splats"]} splats, depth {run["depth"]}, {total} bytes; root + tileset.json '
      f'{first} bytes ({100 * first / total:.1f}%); root error {root["geometricError"]:.4g}')
PY

# plain and no-splat tiles are what the flags say
"$AMGSPLAT" export "$T/torus.hier" -o "$T/plain" --tiles --tile-points 2048 --plain --no-splats -q
grep -o '"KHR_mesh_quantization"\|"KHR_gaussian_splatting"' "$T/plain/tiles/0.glb" >/dev/null &&
  fail "--plain --no-splats tiles carry quantisation or splats"
grep -o '"KHR_gaussian_splatting"' "$T/tiles/tiles/0.glb" >/dev/null || fail "default tiles lack the splats"

# errors
expect_fail 2 "--tile-points needs --tiles" "$AMGSPLAT" export "$T/torus.ply" -o "$T/x.glb" --tile-points 10
expect_fail 1 "cannot create directory" "$AMGSPLAT" export "$T/torus.hier" -o "$T/file" --tiles
expect_fail 1 "cannot create directory" "$AMGSPLAT" export "$T/torus_s.hier" -o "$T/file" --tiles
echo "export_tiles: ok"
