#!/usr/bin/env bash
# Frame budget (issue 18 item 5; BENCHMARKS.md "Frame budget (issue 18)"): the viewer's scripted
# fly-through under `--frame-ms T` in Xvfb, R runs per renderer, each run's median / p10 / p90 frame
# time, tau range and counts, then the median of the run medians and its ratio to T. Timings never
# decide pass or fail (STYLE.md 11); tests/cli/budget.sh is the test.
#
#   bench/bench_budget.sh AMGSPLAT MODEL [T=40] [FRAMES=300] [RUNS=5] [SIZE=800x600] [RENDERERS="square splat"]
# e.g. amgsplat sample ../shared/data/stanford-bunny.obj --method area --points 1000000 -o bunny1m.ply
#      bench/bench_budget.sh build/amgsplat bunny1m.ply
set -euo pipefail
bin=${1:?amgsplat binary}; model=${2:?model}; target=${3:-40}; frames=${4:-300}; runs=${5:-5}
size=${6:-800x600}; renderers=${7:-square splat}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
echo "load: $(uptime)"
echo "model $model, window $size, budget $target ms, $frames frames per run, $runs runs"
for r in $renderers; do
  # full detail (tau 0) at the fly-through's first view, for reference: median of 10 frames
  xvfb-run -a -s "-screen 0 1280x1024x24" "$bin" view "$model" --renderer "$r" --tau 0 --frames 10 --size "$size" \
    --json -q >"$out/full_$r.json"
  for i in $(seq "$runs"); do
    xvfb-run -a -s "-screen 0 1280x1024x24" "$bin" view "$model" --renderer "$r" --frame-ms "$target" --fly "$frames" \
      --size "$size" --stats-json "$out/${r}_$i.json" -q
  done
  python3 - "$out" "$r" "$runs" "$target" <<'PY'
import json, statistics, sys
out, r, runs, target = sys.argv[1], sys.argv[2], int(sys.argv[3]), float(sys.argv[4])
full = json.load(open('%s/full_%s.json' % (out, r)))
print('%s: full detail %.1f ms per frame (%d points, first view)' % (r, full['median_frame_ms'], full['count']))
meds = []
for i in range(1, runs + 1):
    j = json.load(open('%s/%s_%d.json' % (out, r, i)))
    meds.append(j['median_frame_ms'])
    within = sum(abs(f['frame_ms'] / target - 1) <= 0.15 for f in j['per_frame']) / len(j['per_frame'])
    print('  run %d: median %.1f ms, p10 %.1f, p90 %.1f, %.0f%% of frames within 15%%, tau %.3g..%.3g px, '
          '%d..%d splats, depth limit min %s' % (i, j['median_frame_ms'], j['p10_frame_ms'], j['p90_frame_ms'],
          100 * within, j['tolerance_min'], j['tolerance_max'], j['count_min'], j['count_max'],
          min((f['depth_limit'] for f in j['per_frame'] if f['depth_limit']), default='none')))
m = statistics.median(meds)
print('  median of the %d run medians: %.1f ms = %.3f T' % (runs, m, m / target))
PY
done
