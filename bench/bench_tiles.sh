#!/usr/bin/env bash
# Streamed tileset of a large point set (issue 32 "Done when" 2 and 3; BENCHMARKS.md "Streamed
# tilesets (issue 32)", docs/web.md): `export --tiles` of a point file under /usr/bin/time -v (wall
# time, peak RSS), then the page in headless Chromium (web/test/tiles.mjs: bytes fetched by the
# first frame as a share of the tileset's, the picture once refined) against `amgsplat render` of
# the same points at the same view (SSIM, imgdiff), and CesiumJS loading the tileset
# (web/test/cesium.mjs). Runs R times and prints the median of export wall time and RSS. Timings
# never decide pass or fail (STYLE.md 11); tests/cli/export_tiles.sh and web_tiles.sh are the tests.
#
#   bench/bench_tiles.sh AMGSPLAT POINTS.ply OUTDIR [VIEW=60,15] [SIZE=512x512] [RUNS=3]
# e.g. amgsplat sample ../shared/data/spot_triangulated.obj --texture ../shared/data/spot_texture.png \
#        --points 10000000 -o spot10m.ply
#      bench/bench_tiles.sh build/amgsplat spot10m.ply /tmp/tiles
# OUTDIR keeps the tileset, the streamed .hier of the reference render and the PNGs (web_first.png,
# web_refined.png, render.png) to look at.
set -euo pipefail
bin=${1:?amgsplat binary}; ply=${2:?point file}; out=${3:?output directory}
view=${4:-60,15}; size=${5:-512x512}; runs=${6:-3}
web="$(cd "$(dirname "$0")/../web" && pwd)"
chromium="${CHROMIUM:-/usr/bin/chromium}"
mkdir -p "$out"
echo "load: $(uptime)"
echo "input $ply ($(stat -c %s "$ply") bytes), view $view, $size, $runs runs"
for i in $(seq "$runs"); do
  rm -rf "$out/tiles"
  /usr/bin/time -v "$bin" export "$ply" -o "$out/tiles" --tiles --json -q >"$out/export.json" 2>"$out/time_$i.txt"
done
python3 - "$out" "$runs" <<'PY'
import json, re, statistics, sys
out, runs = sys.argv[1], int(sys.argv[2])
wall, rss = [], []
for i in range(1, runs + 1):
    t = open(f'{out}/time_{i}.txt').read()
    m = re.search(r'Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (?:(\d+):)?(\d+):([\d.]+)', t)
    wall.append(int(m.group(1) or 0) * 3600 + int(m.group(2)) * 60 + float(m.group(3)))
    rss.append(int(re.search(r'Maximum resident set size \(kbytes\): (\d+)', t).group(1)) / 1024)
e = json.load(open(f'{out}/export.json'))
print(f"export --tiles: {e['points']} points -> {e['tiles']} tiles (refine {e['refine']}, depth {e['depth']}, "
      f"largest {e['largest_tile']} points), {e['bytes'] / 1e6:.2f} MB ({e['bytes'] / e['points']:.2f} bytes a point), "
      f"tileset.json {e['json_bytes'] / 1e3:.1f} kB")
print(f"  wall {statistics.median(wall):.2f} s median of {runs} ({', '.join('%.2f' % w for w in wall)}); "
      f"peak RSS {statistics.median(rss):.0f} MiB median (max {max(rss):.0f})")
PY

# the page: first frame and refined picture
node "$web/test/tiles.mjs" "$out/tiles" "$out/web" --view "$view" --size "$size" --chromium "$chromium" \
  --timeout 600 >"$out/stream.json"
# the reference: amgsplat render of the same points, from their streamed hierarchy (the cut the
# tiles hold; unlit, as the page draws discs without normals)
"$bin" convert "$ply" -o "$out/ref.hier" -q
"$bin" render "$out/ref.hier" -o "$out/render.png" --view "$view" --size "$size" --unlit -q
"$bin" imgdiff "$out/web_refined.png" "$out/render.png" --json >"$out/refined_diff.json"
"$bin" imgdiff "$out/web_first.png" "$out/render.png" --json >"$out/first_diff.json"
python3 - "$out" <<'PY'
import json, sys
out = sys.argv[1]
s = json.load(open(f'{out}/stream.json'))
total, f, r = s['tileset_bytes'], s['first_frame'], s['refined']
print(f"page: first frame after {f['bytes']} bytes = {100 * f['bytes'] / total:.2f}% of {total} "
      f"(server {f['server_bytes']}), {f['requests']} requests, {f['points']} points, {f['ms']:.0f} ms")
print(f"      refined: {r['tiles']} tiles, {r['points']} points, {r['bytes']} bytes "
      f"({100 * r['bytes'] / total:.2f}%), error target {r['error_target']:.2f} px")
a, b = json.load(open(f'{out}/first_diff.json')), json.load(open(f'{out}/refined_diff.json'))
print(f"SSIM vs amgsplat render: refined {b['ssim']:.4f} (PSNR {b['psnr']:.2f} dB), first frame {a['ssim']:.4f}")
PY
node "$web/test/cesium.mjs" "$out/tiles" --chromium "$chromium" --timeout 600 --png "$out/cesium.png"
