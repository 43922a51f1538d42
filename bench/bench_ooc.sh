#!/usr/bin/env bash
# The out-of-core hierarchy (issue 28) measured at several sizes: `synth terrain` streams N points to
# binary PLY, `convert IN -o OUT.hier` builds the streamed hierarchy (points/s, peak RSS, wall and
# CPU time), `render` draws a view of the whole set and a close-up from it (peak RSS, points loaded,
# seconds). Peak RSS and CPU times come from /usr/bin/time -v; the load average is printed, since
# wall time on a shared machine is not the work's. Timings never decide pass or fail (STYLE.md 11);
# tests/cli/ooc.sh is the test. 1e9 points need about 15 GB for the PLY, 16 GB for the .hier and
# 16 GB of chunk files at once: run it by hand (SIZES=1e9) with DIR on a disk with 50 GB free.
#
#   bench/bench_ooc.sh AMGSPLAT [DIR=/tmp/asp-ooc] [SIZES="1e6 1e7 1e8"] [MEMORY=2G] [KEEP=0]
set -euo pipefail
bin=${1:?amgsplat binary}; dir=${2:-/tmp/asp-ooc}; sizes=${3:-${SIZES:-1e6 1e7 1e8}}; memory=${MEMORY:-2G}
mkdir -p "$dir"
echo "machine: $(nproc) cores, $(free -g | awk '/Mem:/ {print $2}') GB; disk: $(df -h "$dir" | awk 'NR == 2 {print $4}') free"
# the ceiling: raw sequential write and read of the disk (direct I/O, 2 GiB)
dd if=/dev/zero of="$dir/dd.tmp" bs=16M count=128 oflag=direct 2>&1 | tail -1 | sed 's/^/disk write: /'
dd if="$dir/dd.tmp" of=/dev/null bs=16M iflag=direct 2>&1 | tail -1 | sed 's/^/disk read:  /'
rm -f "$dir/dd.tmp"
# run LABEL CMD...: the command under /usr/bin/time -v; prints wall, CPU, peak RSS and the load
run() {
  local label=$1; shift
  /usr/bin/time -v "$@" >"$dir/out.txt" 2>"$dir/time.txt" || { cat "$dir/time.txt" >&2; exit 1; }
  python3 - "$label" "$dir/time.txt" <<'PY'
import os, re, sys
t = open(sys.argv[2]).read()
def g(k):
    m = re.search(re.escape(k) + r':\s*(.*)', t)
    return m.group(1).strip() if m else '?'
wall = g('Elapsed (wall clock) time (h:mm:ss or m:ss)')
parts = [float(x) for x in wall.split(':')]
secs = sum(p * 60 ** i for i, p in enumerate(reversed(parts)))
cpu = float(g('User time (seconds)')) + float(g('System time (seconds)'))
print('%-22s wall %8.1f s  cpu %8.1f s  peak RSS %7.0f MB  load %s' % (
    sys.argv[1], secs, cpu, int(g('Maximum resident set size (kbytes)')) / 1024, os.getloadavg()[0]))
open(sys.argv[2] + '.secs', 'w').write('%f %f' % (secs, cpu))
PY
}
for n in $sizes; do
  tag=$(python3 -c "print('%dM' % (float('$n') / 1e6))")
  ply="$dir/terrain_$tag.ply"; hier="$dir/terrain_$tag.hier"
  [[ -s $ply ]] || run "synth $tag" "$bin" synth terrain --points "$n" -o "$ply" -q
  run "convert $tag" "$bin" convert "$ply" -o "$hier" --memory "$memory" --json
  python3 - "$dir/out.txt" "$dir/time.txt.secs" <<'PY'
import json, sys
d = json.load(open(sys.argv[1])); secs, cpu = map(float, open(sys.argv[2]).read().split())
print('  %d points, %d nodes, depth %d, %d chunks; %.2f M points/s wall, %.2f M points/s per CPU-second; '
      'bounds %.1f s, count %.1f s, distribute %.1f s, index %.1f s' % (
      d['points'], d['nodes'], d['depth'], d['chunks'], d['points'] / secs / 1e6, d['points'] / cpu / 1e6,
      d['seconds_bounds'], d['seconds_count'], d['seconds_distribute'], d['seconds_index']))
PY
  for v in "whole 30,40" "close 20,35,0.05"; do
    set -- $v
    run "render $tag $1" "$bin" render "$hier" -o "$dir/terrain_${tag}_$1.png" --size 1024x1024 --up z \
      --view "$2" --memory "$memory" --json
    python3 -c "import json; d = json.load(open('$dir/out.txt')); print('  %d points loaded, %s, %.1f ms per view' % (d['points'], d['gl_renderer'], d['view_ms']))"
  done
  [[ ${KEEP:-0} == 1 ]] || rm -f "$ply" "$hier"
done
