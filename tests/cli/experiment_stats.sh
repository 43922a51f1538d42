# amgsplat experiment analyze and ttest (issue 15, seed 004 chapter 4): the synthetic study in
# tests/data/experiment/study (built by make_logs.py with known grades and naming times, one log cut
# off mid-line, one with a cut line glued to the next) analyses; the JSON report holds the grades,
# the A->B improvements and their pooled t, the naming times and the lost frames; the charts are
# real PNGs. ttest reproduces the seed's Table 4.7 t = 1.522. Bad logs fail naming file and line.
# Needs the 'experiment' dispatcher: without it this test FAILS (the lead merges both branches).
source "$(dirname "$0")/common.sh"
SRC="${ASP_TEST_SRC:?ASP_TEST_SRC must name tests/}"
STUDY="$SRC/data/experiment/study"

expect_exit 0 "$AMGSPLAT" experiment analyze -h
grep -F 'experiment analyze DIR -o REPORT_DIR' "$T/out" >/dev/null || fail "analyze -h prints no usage"
expect_exit 0 "$AMGSPLAT" experiment ttest -h

# ---- ttest: seed 004 Table 4.7 (pooled, 9 df) and Welch's test of the same figures
expect_exit 0 "$AMGSPLAT" experiment ttest 5,7.6,5.0 6,-8.9,23.6 --json
python3 - "$T/out" <<'PY' || fail "ttest Table 4.7"
import json, sys
r = json.load(open(sys.argv[1]))
assert r["test"] == "pooled" and r["df"] == 9, r
assert abs(r["t"] - 1.522) < 0.0005, r["t"]               # the seed prints 1.522
assert 0.05 < r["p_greater"] < 0.10, r["p_greater"]        # "between the 0.05 and 0.10 percentiles"
lo, hi = r["diff_ci"]; assert lo < 16.5 < hi and lo < 0, r["diff_ci"]
PY
expect_exit 0 "$AMGSPLAT" experiment ttest 5,7.6,5.0 6,-8.9,23.6 --welch --json
python3 -c "
import json,sys; r=json.load(open('$T/out'))
assert r['test']=='welch' and abs(r['t']-1.6682)<1e-3 and abs(r['df']-5.533)<1e-3, r" || fail "ttest --welch"
expect_exit 0 "$AMGSPLAT" experiment ttest 10,8.7,8.1 5,-4.3,19.7
grep -F 't = 1.8487, df = 13' "$T/out" >/dev/null || fail "Table 4.5 text output: $(cat "$T/out")"
# one sample: the paired test of differences against 0 (t_{0.975,3} = 3.182: p 0.025)
expect_exit 0 "$AMGSPLAT" experiment ttest 4,3.182,2 --json
python3 -c "
import json; r=json.load(open('$T/out'))
assert r['test']=='one-sample' and r['df']==3 and abs(r['t']-3.182)<1e-9 and abs(r['p_greater']-0.025)<1e-4, r" || fail "one-sample ttest"
expect_fail 2 "--welch compares two samples" "$AMGSPLAT" experiment ttest 4,3,2 --welch
expect_fail 2 "expected N,MEAN,SD" "$AMGSPLAT" experiment ttest 5,7.6 6,-8.9,23.6
expect_fail 2 "expected N,MEAN,SD" "$AMGSPLAT" experiment ttest 2.5,1,1 6,-8.9,23.6
expect_fail 2 "--level" "$AMGSPLAT" experiment ttest 5,1,1 6,2,1 --level 1.5
expect_fail 1 "standard error is 0" "$AMGSPLAT" experiment ttest 5,1,0 6,2,0

# ---- analyze the synthetic study
expect_exit 0 "$AMGSPLAT" experiment analyze "$STUDY" -o "$T/report" --json
python3 - "$T/out" "$T/report" <<'PY' || fail "analyze report"
import json, sys, math
summary = json.load(open(sys.argv[1]))
assert summary["logs"] == 24 and summary["subjects"] == 4, summary
assert summary["lost_frames"] == 2, summary
def strict(c):
    raise ValueError("report.json holds %s, which JSON does not have" % c)
r = json.load(open(sys.argv[2] + "/report.json"), parse_constant=strict)
assert r["format"] == "amgsplat-experiment-report 1"
assert r["counts"]["lost_frames"] == 2 and r["counts"]["answers"] == 16
assert r["counts"]["answers_mismatch"] == 0, r["counts"]
logs = {(l["subject"], l["test"], l["run"]): l for l in r["logs"]}
cut = logs[("S02", "lowspeed", "B")]
assert cut["lost_frames"] == 1 and cut["first_lost_line"] == 13 and cut["frames"] == 11, cut
glued = logs[("S03", "far", "A")]
assert glued["lost_frames"] == 1 and glued["frames"] == 20, glued
# grades built into the tracks: along 100%, backwards, sideways and out of bounds 0%
want = {("S01", "A"): 0.8, ("S01", "B"): 0.9, ("S02", "A"): 0.6, ("S02", "B"): 0.8,
        ("S03", "A"): 0.7, ("S03", "B"): 0.5, ("S04", "A"): 0.9, ("S04", "B"): 0.6}
for (s, run), g in want.items():
    got = logs[(s, "lowspeed", run)]["grade"]["grade"]
    assert abs(got - g) < 1e-9, (s, run, got, g)
assert logs[("S03", "lowspeed", "B")]["grade"]["out"] == 5
nav = r["navigation"]["lowspeed"]
imp = {i["group"]: i for i in nav["improvement"]}
assert abs(imp["control"]["mean"] - 15) < 1e-9 and abs(imp["variable points"]["mean"] + 25) < 1e-9, imp
t = [x for x in nav["tests"] if x["compared"] == "improvement"][0]
# control 10, 20 against variable -20, -30: difference 40, pooled sd sqrt(50), t = 40 / sqrt(50) = 5.657, df 2
assert abs(t["pooled"]["t"] - 40 / math.sqrt(50)) < 1e-9 and t["pooled"]["df"] == 2, t
assert 0.01 < t["pooled"]["p_greater"] < 0.02, t
assert t["welch"]["diff_ci"][0] > 0
paired = {p["group"]: p for p in nav["paired"]}
# variable: -20, -30: mean -25, se 5, t = -5 with 1 df
assert abs(paired["variable points"]["t"] + 5) < 1e-9 and paired["variable points"]["df"] == 1, paired
# recognition, run B: far polygons 1.0 and 1.4 s; points 2.0 s correct, S04 "dog" wrong
rec = {(x["test"], x["condition"]): x for x in r["recognition"]["rows"]}
far_poly, far_pts = rec[("far", "polygons")], rec[("far", "points")]
assert far_poly["correct"] == 2 and abs(far_poly["naming_s"]["mean"] - 1.2) < 1e-9, far_poly
assert far_pts["correct"] == 1 and far_pts["incorrect"] == 1 and far_pts["percent_correct"] == 50, far_pts
near = [x for x in r["recognition"]["tests"] if x["test"] == "near"][0]
# near: polygons 0.8, 1.2 s; points 2.2, 2.6 s: difference 1.4, pooled variance 0.08, t = 1.4 / sqrt(0.08)
assert abs(near["pooled"]["t"] - 1.4 / math.sqrt(0.08)) < 1e-6 and near["pooled"]["df"] == 2, near
# frame time: points were built twice as slow as polygons
ft = {(x["test"], x["condition"]): x for x in r["frame_time"]}
assert 1.8 < ft[("lowspeed", "points")]["mean"] / ft[("lowspeed", "polygons")]["mean"] < 2.2
PY
for f in report.md logs.csv frame_time.csv recognition.csv navigation.csv improvement.csv; do
  [[ -s "$T/report/$f" ]] || fail "report lacks $f"
done
grep -F '**2 frames lost**' "$T/report/report.md" >/dev/null || fail "report.md does not say how many frames were lost"
grep -E '^lowspeed,improvement,variable points,2,2,' "$T/report/improvement.csv" >/dev/null || fail "improvement.csv"
# charts: PNGs of the right size with more than one colour in them (bars, markers, error bars)
for png in frame_time_vs_drawn drawn_far drawn_near drawn_lowspeed grades_lowspeed; do
  [[ -s "$T/report/$png.png" ]] || fail "missing $png.png"
  check "$T/report/$png.png" "w >= 600 and h >= 300 and len(set(px(x, y)[:3] for x in range(0, w, 5) for y in range(0, h, 5))) > 3"
done
# polygons blue, points vermillion (Okabe-Ito) in the histogram's plot area (left of the legend): both drawn
check "$T/report/drawn_lowspeed.png" "any(px(x, y)[0] > 180 and px(x, y)[1] < 110 and px(x, y)[2] < 60 for x in range(60, w - 140) for y in range(h)) and any(px(x, y)[2] > 150 and px(x, y)[0] < 80 for x in range(60, w - 140) for y in range(h))"

# ---- bad input: clean errors naming the file and line, never a crash
mkdir -p "$T/bad/S01" "$T/fmt/S01" "$T/empty"
printf '{"type":"frame","i":0,"t":0,"frame_ms":1,"pos":[0,0,0]}\n' >"$T/bad/S01/far-A.jsonl"
expect_fail 1 "far-A.jsonl' line 1: expected the header" "$AMGSPLAT" experiment analyze "$T/bad" -o "$T/r2"
printf '{"type":"header","format":"amgsplat-experiment-log 9","subject":"S01","test":"far","run":"A","condition":"points"}\n' >"$T/fmt/S01/far-A.jsonl"
expect_fail 1 "expected format 'amgsplat-experiment-log 1'" "$AMGSPLAT" experiment analyze "$T/fmt" -o "$T/r3"
expect_fail 1 "no experiment log" "$AMGSPLAT" experiment analyze "$T/empty" -o "$T/r4"
expect_fail 1 "not a directory" "$AMGSPLAT" experiment analyze "$T/nonexistent" -o "$T/r5"
expect_fail 2 "missing -o" "$AMGSPLAT" experiment analyze "$STUDY"
expect_fail 2 "is the input" "$AMGSPLAT" experiment analyze "$STUDY" -o "$STUDY/."
printf 'x' >"$T/afile"
expect_fail 1 "cannot create report directory" "$AMGSPLAT" experiment analyze "$STUDY" -o "$T/afile"
[[ ! -e "$T/r2/report.md" ]] || fail "a failed analysis left a report"
echo "ok"
