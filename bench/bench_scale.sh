#!/usr/bin/env bash
# Scaling benchmark of the AMG decomposition (issue 19): the Stanford bunny
# sampled with N points (binary PLY), `amgsplat decompose` timed with
# /usr/bin/time -v for each N and rank count P, with its peak RSS, the
# per-stage split (decompose --json "seconds"), the growth exponent of time and
# memory (least squares of log t against log N) and a paper estimate for 10^9
# points on a cluster from the measured per-rank figures. Prints a Markdown
# table (the one in BENCHMARKS.md, "Decomposition scale (issue 19)").
#
# usage: bench/bench_scale.sh [--big] [--huge] [--sizes "1e6 2e6"] [--ranks "1 2"] [--repeat R]
#                             [--work DIR] [--amgsplat PATH]
#   default sizes 1M 2M 4M 8M; --big adds 16M, --huge adds 50M (about 20 GB: run it alone,
#   under `ulimit -v`). P > 1 runs `mpirun -np P amgsplat decompose`, and only when this build's
#   decompose says it runs on MPI ranks (its -h names mpirun); otherwise those rows are skipped.
#   --repeat R: median of R runs per cell (default 1). Samples are kept in the work folder
#   (default /tmp/amgsplat-scale) so a second run does not sample again.
# Environment: ASP_TEST_DATA (the models, default ../shared/data), THREADS (default: all).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
A=$here/build/amgsplat
D=${ASP_TEST_DATA:-$here/../shared/data}
sizes="1e6 2e6 4e6 8e6"
ranks="1 2"
repeat=1
work=/tmp/amgsplat-scale
while [ $# -gt 0 ]; do
    case $1 in
    --big) sizes="$sizes 16e6" ;;
    --huge) sizes="$sizes 50e6" ;;
    --sizes) sizes=$2; shift ;;
    --ranks) ranks=$2; shift ;;
    --repeat) repeat=$2; shift ;;
    --work) work=$2; shift ;;
    --amgsplat) A=$2; shift ;;
    -h | --help) sed -n '2,18p' "$0"; exit 0 ;;
    *) echo "bench_scale: unknown option '$1'" >&2; exit 2 ;;
    esac
    shift
done
[ -x "$A" ] || { echo "bench_scale: no amgsplat at '$A' (build it, or --amgsplat PATH)" >&2; exit 2; }
[ -f "$D/stanford-bunny.obj" ] || { echo "bench_scale: no '$D/stanford-bunny.obj' (set ASP_TEST_DATA)" >&2; exit 2; }
[ -x /usr/bin/time ] || { echo "bench_scale: needs GNU time at /usr/bin/time (peak RSS)" >&2; exit 2; }
mkdir -p "$work"
threads=()
[ -n "${THREADS:-}" ] && threads=(--threads "$THREADS")
distributed=0
"$A" decompose -h 2>&1 | grep -q mpirun && distributed=1

results=$work/results.tsv
: >"$results"
for n in $sizes; do
    count=$(python3 -c "print(int(float('$n')))")
    ply=$work/bunny_$count.ply
    if [ ! -s "$ply" ]; then
        echo "== sampling $count points" >&2
        "$A" sample "$D/stanford-bunny.obj" --points "$count" -o "$ply" --quiet
    fi
    for p in $ranks; do
        if [ "$p" -gt 1 ] && [ $distributed = 0 ]; then
            echo "== N $count, P $p: skipped (this build's decompose does not run on MPI ranks)" >&2
            continue
        fi
        for r in $(seq "$repeat"); do
            echo "== N $count, P $p, run $r ($(uptime | sed 's/.*load/load/'))" >&2
            run=() opts=("${threads[@]}")
            # one thread per rank (ranks and threads together must not exceed the cores, docs/mpi.md);
            # as root Open MPI wants the two variables, given to mpirun only (hypre_bridge.c, issue 13)
            [ "$p" -gt 1 ] && run=(env OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
                mpirun -np "$p" --oversubscribe) opts=(--threads 1)
            # GNU time's maximum resident set size of mpirun is that of its largest child: one rank's peak
            /usr/bin/time -v -o "$work/time.txt" "${run[@]}" "$A" decompose "$ply" -o "$work/out.amg" --json \
                "${opts[@]}" >"$work/out.json"
            load=$(cut -d' ' -f1 /proc/loadavg)
            python3 - "$work/out.json" "$work/time.txt" "$count" "$p" "$load" >>"$results" <<'PY'
import json, re, sys
j = json.load(open(sys.argv[1]))
t = open(sys.argv[2]).read()
wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (\S+)", t).group(1).split(":")
wall = sum(float(x) * 60 ** i for i, x in enumerate(reversed(wall)))
rss_kb = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", t).group(1))
s = j["seconds"]
print("\t".join(str(v) for v in [sys.argv[3], sys.argv[4], wall, rss_kb, s["neighbours"], s["classifier"],
                                  s["fans"], s["assembly"], s["amg"], j["levels"], sys.argv[5]]))
PY
        done
    done
done
rm -f "$work/out.amg"

python3 - "$results" <<'PY'
import math, statistics, sys
rows = [l.split("\t") for l in open(sys.argv[1]) if l.strip()]
cells = {}
for r in rows:
    cells.setdefault((int(r[0]), int(r[1])), []).append([float(x) for x in r[2:]])
def med(v, k):
    return statistics.median(x[k] for x in v)
# P > 1: the peak RSS is the largest rank's, and bytes/point are per point that rank owns (N / P)
print("| N | P | wall (s) | peak RSS (per process) | bytes/point (per process) | neighbours | classifier | fans | assembly | AMG | levels | load |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|")
for (n, p), v in sorted(cells.items()):
    wall, rss = med(v, 0), med(v, 1) * 1024
    print(f"| {n / 1e6:g}M | {p} | {wall:.2f} | {rss / 2**20:.0f} MB | {rss * p / n:.0f} | "
          + " | ".join(f"{med(v, k):.2f}" for k in range(2, 7)) + f" | {med(v, 7):.0f} | {med(v, 8):.1f} |")
for p in sorted({p for _, p in cells}):
    pts = sorted((n, med(v, 0), med(v, 1) * 1024) for (n, q), v in cells.items() if q == p)
    if len(pts) < 2:
        continue
    def slope(k):
        xs = [math.log(x[0]) for x in pts]
        ys = [math.log(x[k]) for x in pts]
        mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
        return sum((a - mx) * (b - my) for a, b in zip(xs, ys)) / sum((a - mx) ** 2 for a in xs)
    at, am = slope(1), slope(2)
    n, t, m = pts[-1]
    print(f"\nP = {p}: time grows as N^{at:.2f}, peak memory as N^{am:.2f} "
          f"({len(pts)} sizes, {pts[0][0] / 1e6:g}M..{n / 1e6:g}M).")
    # Paper estimate for 10^9 points: each rank holds N/P points at the measured bytes per point and runs at the
    # measured rate; the distributed run adds halo exchange and hypre's communication, not modelled here.
    bpp = m * p / n  # per point a process owns
    t1e9 = t * (1e9 / n) ** at
    for ranks, gb in ((64, 16), (256, 4)):
        per_rank = 1e9 / ranks
        print(f"10^9 points on {ranks} ranks ({gb} GB each): {per_rank / 1e6:.1f}M points and "
              f"{per_rank * bpp / 2**30:.1f} GB per rank at {bpp:.0f} B/point; "
              f"{t * (per_rank * p / n) ** at:.0f} s if the ranks scaled perfectly "
              f"(one process: {t1e9 / 3600:.1f} h, {1e9 * bpp / 2**30:.0f} GB).")
PY
