# ctest-label: e2e
# amgsplat experiment, issue 29: three observer subjects fill the control group and the two variable
# conditions (points, primitives) one each, keeping their group in every test; analyze reports the
# design, frame time per run (mean, median, p95), the condition-vs-polygons frame-time test over run
# means (not frames) and a recognition comparison with a row per condition; a study missing a group
# is warned about. The terrain path stands out from the ground (a green verge), and a person's
# practice walks, flies, and ends on a "practice over" screen before the first test.
source "$(dirname "$0")/common.sh"

G=/usr/share/glmark2/models
for m in bunny.obj cat.3ds horse.3ds; do
  [[ -r "$G/$m" ]] || asp_skipped+=("$G/$m (Debian package glmark2-data)")
done
((${#asp_skipped[@]} == 0)) || exit 0

run() { "$AMGSPLAT" experiment run --observer --seed 1 --short --cache "$T/cache" -q "$@"; }
expect_exit 0 run -o "$T/d3" --subjects 3 --screenshots "$T/shots3"
if grep -F "unbalanced" "$T/err" >/dev/null; then fail "3 subjects over 3 groups warned: $(cat "$T/err")"; fi
expect_exit 0 "$AMGSPLAT" experiment analyze "$T/d3" -o "$T/r3" --json
cp "$T/out" "$T/r3.json"
if grep -F "unbalanced" "$T/err" >/dev/null; then fail "analyze warned about a balanced study: $(cat "$T/err")"; fi
# the same study without its third subject: one group is empty
cp -r "$T/d3" "$T/a"
rm -r "$T/a/S03"
g3=$(python3 -c "import json; print(json.loads(open('$T/d3/S03/far-B.jsonl').readline())['condition'])")
[[ "$g3" == polygons ]] && g3=control
expect_exit 0 "$AMGSPLAT" experiment analyze "$T/a" -o "$T/r2" -q
grep -E "warning: unbalanced design: the groups have .*$g3 0" "$T/err" >/dev/null ||
  fail "analyze of 2 subjects does not warn of an empty $g3 group: $(cat "$T/err")"
grep -F "**Warning: unbalanced design" "$T/r2/report.md" >/dev/null || fail "report.md of 2 subjects has no warning"
python3 - "$T" <<'PY' || fail "balanced design and per-run analysis"
import json, sys
T = sys.argv[1]
tests = ["far", "near", "lowspeed", "highspeed"]
s = json.load(open(T + "/d3/study.json"))
d = s["design"]
assert d["rule"] == "balanced" and d["groups"] == ["control", "points", "primitives"], d
assert d["balanced"] is True and "warning" not in d and d["runs_b"] == {"control": 4, "points": 4, "primitives": 4}, d
# one subject per group, each keeping its group's condition in every test's run B
groups = {}
for subj in ["S01", "S02", "S03"]:
    conds = set()
    for t in tests:
        h = json.loads(open("%s/d3/%s/%s-B.jsonl" % (T, subj, t)).readline())
        assert json.loads(open("%s/d3/%s/%s-A.jsonl" % (T, subj, t)).readline())["condition"] == "polygons"
        conds.add(h["condition"])
    assert len(conds) == 1, (subj, conds)
    groups[subj] = conds.pop()
assert sorted(groups.values()) == ["points", "polygons", "primitives"], groups
r2 = json.load(open(T + "/r2/report.json"))
assert r2["design"]["balanced"] is False and "unbalanced" in r2["design"]["warning"], r2["design"]
# analyze: the design, one frame-time row per run, tests over run means, recognition rows
summary = json.load(open(T + "/r3.json"))
assert summary["balanced"] is True and summary["groups"] == 3 and "design_warning" not in summary, summary
r = json.load(open(T + "/r3/report.json"))
assert r["design"]["balanced"] is True and {g["group"]: g["subjects"] for g in r["design"]["groups"]} == \
    {"control": 1, "points": 1, "primitives": 1}, r["design"]
runs = r["frame_time_runs"]
assert len(runs) == 24, len(runs)
logs = {(l["subject"], l["test"], l["run"]): l for l in r["logs"]}
for x in runs:
    assert x["frames"] > 0 and x["frames"] == logs[(x["subject"], x["test"], x["run"])]["frames"], x
    assert 0 < x["median_ms"] <= x["p95_ms"] <= x["max_ms"] and x["min_ms"] <= x["mean_ms"] <= x["max_ms"], x
assert r["frame_time_unit"] == "ms per frame"
ft = r["frame_time_tests"]
# every variable condition against polygons in every test, over run means: 1 run against 4 (3 A + 1 control B)
assert {(x["test_name"], x["condition"]) for x in ft} == {(t, c) for t in tests for c in ("points", "primitives")}, ft
for x in ft:
    assert x["unit"] == "run mean" and x["runs"] == 1 and x["runs_against"] == 4, x
    assert x["diff"] is not None and "no test" in x["note"], x
rec = r["recognition"]["tests"]
want = {(t, c) for t in ("far", "near") for c in ("points", "primitives")}
assert {(x["test"], x["condition"]) for x in rec} == want, rec
for x in rec:
    assert x["n_polygons"] == 1 and x["n"] <= 1 and "note" in x, x
    assert x["n"] == 0 or x["diff"] is not None, x
md = open(T + "/r3/report.md").read()
assert "### Frame time per run" in md and "| S02 | lowspeed | B |" in md, md[:2000]
sec = md.split("### Frame time per run")[1].split("###")[0]
assert sum(1 for l in sec.splitlines() if l.startswith("| S0")) == 24, sec
rows = md.split("Naming time, condition minus polygons")[1].split("##")[0]
assert sum(1 for l in rows.splitlines() if l.startswith("| far |") or l.startswith("| near |")) == 4, rows
PY

# the path stands out: sand on the path ahead, a green verge beside it (the old colours had 0% green)
shot="$T/shots3/lowspeed-polygons.png"
sandy="(px(x, y)[0] > 60 and px(x, y)[0] - px(x, y)[2] > 0.22 * px(x, y)[0])"
check "$shot" "sum(1 for x in range(w) for y in range(h * 3 // 4, h) if $sandy) > 0.25 * w * h / 4"
green="(px(x, y)[1] > px(x, y)[0] + 15 and px(x, y)[1] > px(x, y)[2] + 15)"
check "$shot" "sum(1 for x in range(w) for y in range(h) if $green) > 0.03 * w * h"

# a person's practice: walking, then flying, then the "practice over" screen before the first test;
# '.' keys wait on a screen (or do nothing while walking) until the practice run's time is up
dots=$(printf '.%.0s' $(seq 1500))
K=">$(printf 'W%.0s' $(seq 30))$dots>$dots>"
practice=("$AMGSPLAT" experiment run --subject P-02 --seed 2 --short --cache "$T/cache" -o "$T/pp" --size 320x200
          --practice --keys "$K" --screenshots "$T/ppshots")
if command -v xvfb-run >/dev/null; then
  expect_exit 0 xvfb-run -a -s "-screen 0 1024x768x24" "${practice[@]}"
elif [[ -n "${DISPLAY:-}" ]]; then
  expect_exit 0 "${practice[@]}"
else
  fail "no xvfb-run and no DISPLAY: install xvfb (scripts/bootstrap.sh) to test the window for people"
fi
python3 - "$T/err" <<'PY' || fail "practice order: $(cat "$T/err")"
import re, sys
lines = open(sys.argv[1]).read().splitlines()
at = lambda pat: next(i for i, l in enumerate(lines) if re.search(pat, l))
walk, fly = at(r"practice: lowspeed over, [1-9]\d* frames"), at(r"practice: highspeed over, [1-9]\d* frames")
first = at(r"^P-02 ")
assert walk < fly < first, (walk, fly, first)
PY
for f in practice-lowspeed practice-highspeed practice-over; do
  [[ -s "$T/ppshots/$f.png" ]] || fail "no $f.png"
  check "$T/ppshots/$f.png" "sum(1 for x in range(w) for y in range(h) if px(x, y)[0] > 200) > 300"
done
# the first test's instructions came after the practice-over screen (the script's last Enter)
[[ -s "$T/ppshots/instructions-near.png" ]] || fail "no instructions after the practice"
