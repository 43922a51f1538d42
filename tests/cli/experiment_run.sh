# ctest-label: e2e
# amgsplat experiment run (issue 15): the machine observer runs the four tests of seed 004 2.3 for two
# subjects; the logs follow docs/experiment-log.md, the same seed gives the same logs apart from
# frame_ms and timestamps, a blank frame leaves the observer where it started, and a subject's logs
# are never overwritten. Two subjects cannot fill three groups: warned (issue 29; the rest of the
# design checks are in experiment_design.sh).
source "$(dirname "$0")/common.sh"

# the recognition objects are Debian's glmark2-data models (the default scene file names them)
G=/usr/share/glmark2/models
for m in bunny.obj cat.3ds horse.3ds; do
  [[ -r "$G/$m" ]] || asp_skipped+=("$G/$m (Debian package glmark2-data)")
done
((${#asp_skipped[@]} == 0)) || exit 0

expect_exit 0 "$AMGSPLAT" experiment run -h
grep -F -- "--observer" "$T/out" >/dev/null || fail "experiment run -h lacks --observer"
expect_fail 2 "give either --observer or --subject" "$AMGSPLAT" experiment run -o "$T/x"
expect_fail 2 "unknown subcommand" "$AMGSPLAT" experiment frobnicate
expect_fail 2 "--conditions takes" "$AMGSPLAT" experiment run --observer -o "$T/x" --conditions polygons

run() { "$AMGSPLAT" experiment run --observer --subjects 2 --seed 1 --short --cache "$T/cache" -q "$@"; }
# the first run fills the cache; the second draws the same cached files
expect_exit 0 run -o "$T/a" --json --screenshots "$T/shots"
cp "$T/out" "$T/a.json"
# 2 subjects cannot fill control + points + primitives: said on stderr even with -q (issue 29)
grep -F "warning: unbalanced design: 2 subjects over 3 groups give subjects control 1, points 1, primitives 0" \
  "$T/err" >/dev/null || fail "no unbalanced-design warning for 2 subjects: $(cat "$T/err")"
expect_exit 0 run -o "$T/b"
# blank: every run B draws nothing
expect_exit 0 run -o "$T/c" --group variable --conditions blank

python3 - "$T" <<'PY' || fail "log checks"
import json, math, os, sys
T = sys.argv[1]
tests = ["far", "near", "lowspeed", "highspeed"]

def lines(path):
    out = []
    for l in open(path).read().split("\n"):
        if l:
            out.append(json.loads(l))
    return out

def check_study(d):
    s = json.load(open(d + "/study.json"))
    assert s["format"] == "amgsplat-study 1" and s["seed"] == 1, s
    assert s["subjects"] == ["S01", "S02"] and s["tests"] == tests, s
    assert s["conditions"] == ["polygons", "points", "primitives"] and s["observer"] is True
    for t in tests:
        sc = s["scenes"][t]
        assert sc["triangles"] > 0 and sc["points"] > 0 and sc["primitives"] > 0, (t, sc)
    json.load(open(d + "/scenes.json"))

def progress(path, pos):
    # arc-length fraction of the path point nearest pos (ground plane)
    best, at, total = 1e30, 0.0, 0.0
    for a, b in zip(path, path[1:]):
        dx, dz = b[0] - a[0], b[2] - a[2]
        l2 = dx * dx + dz * dz
        t = max(0.0, min(1.0, ((pos[0] - a[0]) * dx + (pos[2] - a[2]) * dz) / l2))
        d = math.hypot(a[0] + t * dx - pos[0], a[2] + t * dz - pos[2])
        if d < best:
            best, at = d, total + t * math.sqrt(l2)
        total += math.sqrt(l2)
    return at / total

def check_logs(d):
    res = {}
    for s in ["S01", "S02"]:
        for t in tests:
            for r in "AB":
                L = lines("%s/%s/%s-%s.jsonl" % (d, s, t, r))
                h = L[0]
                assert h["type"] == "header" and h["format"] == "amgsplat-experiment-log 1", h
                assert h["subject"] == s and h["test"] == t and h["run"] == r and h["seed"] == 1, h
                assert h["group"] in ("control", "variable") and h["observer"] is True
                assert h["screen"] == [160, 120] and h["started"].endswith("Z")
                assert r == "B" or h["condition"] == "polygons"
                assert h["group"] == "variable" or h["condition"] == "polygons"
                assert set(h["drawn"]) == {"triangles", "points", "primitives"}
                frames = [o for o in L if o["type"] == "frame"]
                events = [o for o in L if o["type"] == "event"]
                assert len(frames) > 10 and [f["i"] for f in frames] == list(range(len(frames)))
                for f in frames:
                    assert len(f["pos"]) == 3 and len(f["dir"]) == 3 and f["frame_ms"] >= 0
                    assert isinstance(f["keys"], str) and f["drawn"] >= 0
                assert events[-1]["what"] == "end" and L[-1] is events[-1]
                if t in ("far", "near"):
                    assert h["answer_expected"] in h["candidates"] and "path" not in h
                    assert all(len(f["rot"]) == 2 for f in frames)
                    w = [e["what"] for e in events]
                    assert w == ["recognised", "answer", "end"], w
                    assert events[1]["t"] > events[0]["t"] > 0
                else:
                    assert len(h["path"]) >= 16 and h["half_width"] > 0
                    moved = math.hypot(frames[-1]["pos"][0] - frames[0]["pos"][0],
                                       frames[-1]["pos"][2] - frames[0]["pos"][2])
                    res[(s, t, r, h["condition"])] = (progress(h["path"], frames[-1]["pos"]), moved)
        A = lines("%s/%s/answers.jsonl" % (d, s))
        assert len(A) == 4 and {(a["test"], a["run"]) for a in A} == {(t, r) for t in tests[:2] for r in "AB"}
        for a in A:
            assert a["subject"] == s and isinstance(a["correct"], bool) and a["recognition_s"] > 0
    return res

for d in ("a", "b", "c"):
    check_study(T + "/" + d)
ra, rb, rc = (check_logs(T + "/" + d) for d in ("a", "b", "c"))

# same seed, same logs, apart from the measured frame time and the start timestamp
for s in ["S01", "S02"]:
    for name in sorted(os.listdir(T + "/a/" + s)):
        la, lb = lines(T + "/a/%s/%s" % (s, name)), lines(T + "/b/%s/%s" % (s, name))
        for o in la + lb:
            o.pop("frame_ms", None)
            o.pop("started", None)
        assert la == lb, (s, name)

# the observer walks along the path with polygons and goes nowhere on a blank frame
for (s, t, r, c), (p, moved) in rc.items():
    if c == "blank":
        assert p < 0.02 and moved < 0.5, (s, t, r, p, moved)
    else:
        assert moved > 5.0, (s, t, r, p, moved)
print("blank", sorted((k, v) for k, v in rc.items()))

# --json: one row per run
rows = json.load(open(T + "/a.json"))
assert len(rows) == 16 and all(r["frames"] > 0 and r["mean_frame_ms"] > 0 for r in rows), rows
PY

# the reader of the same contract (experiment analyze) takes the logs whole
expect_exit 0 "$AMGSPLAT" experiment analyze "$T/a" -o "$T/report"
grep -F "0 frames lost" "$T/report/report.md" >/dev/null || fail "analyze lost frames of a whole study"
grep -E "^lowspeed,.*,A," "$T/report/navigation.csv" >/dev/null || fail "no lowspeed grades: $(cat "$T/report/navigation.csv")"

# screenshots: every test in every condition, the blank ones a single colour
for t in far near lowspeed highspeed; do
  for c in polygons points primitives blank; do
    [[ -s "$T/shots/$t-$c.png" ]] || fail "no screenshot $t-$c.png"
  done
  check "$T/shots/$t-blank.png" "len({px(x, y) for x in range(w) for y in range(h)}) == 1"
  check "$T/shots/$t-polygons.png" "len({px(x, y) for x in range(w) for y in range(h)}) > 50"
done

# a subject's logs are never overwritten: refused without --resume; --resume keeps every existing log
before=$(cat "$T"/a/S01/*.jsonl | md5sum)
expect_fail 1 "already has logs" run -o "$T/a"
expect_exit 0 run -o "$T/a" --resume
[[ "$(cat "$T"/a/S01/*.jsonl | md5sum)" == "$before" ]] || fail "--resume changed existing logs"
# a missing log is added by --resume
rm "$T/a/S02/far-B.jsonl"
expect_exit 0 run -o "$T/a" --resume
head -1 "$T/a/S02/far-B.jsonl" | grep '"type":"header"' >/dev/null || fail "--resume did not rewrite far-B"

# a person's session in a real window (Xvfb + llvmpipe), driven by scripted keys: seed 2 starts with
# the near test; Enter starts it, W tilts the object, Enter = recognised, "horse" typed, Enter = the
# answer; the script then runs out, which is Esc: run B is aborted and what was recorded stays
K=">WWWWWWWWWWWWWWWWWWWWWWWWWWWWWW>horse>"
person=("$AMGSPLAT" experiment run --subject P-01 --seed 2 --short --cache "$T/cache" -o "$T/p" --size 320x200
        --keys "$K" --screenshots "$T/pshots")
if command -v xvfb-run >/dev/null; then
  expect_exit 0 xvfb-run -a -s "-screen 0 1024x768x24" "${person[@]}"
elif [[ -n "${DISPLAY:-}" ]]; then
  expect_exit 0 "${person[@]}"
else
  fail "no xvfb-run and no DISPLAY: install xvfb (scripts/bootstrap.sh) to test the window for people"
fi
grep -F "stopped by Esc" "$T/err" >/dev/null || fail "no Esc message: $(cat "$T/err")"
python3 - "$T/p/P-01" <<'PY' || fail "person log checks"
import json, sys
d = sys.argv[1]
L = [json.loads(l) for l in open(d + "/near-A.jsonl")]
h = L[0]
assert h["observer"] is False and h["subject"] == "P-01" and h["condition"] == "polygons", h
frames = [o for o in L if o["type"] == "frame"]
ev = [o for o in L if o["type"] == "event"]
assert [e["what"] for e in ev] == ["recognised", "answer", "end"], ev
assert ev[1]["text"] == "horse" and ev[1]["t"] > ev[0]["t"]
assert sum(f["keys"] == "W" for f in frames) == 30 and frames[30]["rot"][1] > frames[0]["rot"][1]
B = [json.loads(l) for l in open(d + "/near-B.jsonl")]
assert [o.get("what") for o in B if o["type"] == "event"] == ["abort", "end"], B
A = [json.loads(l) for l in open(d + "/answers.jsonl")]
assert len(A) == 1 and A[0]["answer"] == "horse" and A[0]["correct"] is True, A
PY
# the instruction screen as the window showed it: light text on a dark screen
check "$T/pshots/instructions-near.png" "sum(1 for x in range(w) for y in range(h) if px(x, y)[0] > 200) > 500"
# ... covering the whole window with the screen's colour, the text block centred and as wide as
# fits (the text overlay's fill, measure and scale; 320 x 200 here)
check "$T/pshots/instructions-near.png" "px(0, 0)[:3] == (30, 32, 40) and px(w - 1, h - 1)[:3] == (30, 32, 40)"
lit="[(x, y) for x in range(w) for y in range(h) if px(x, y)[0] > 200]"
check "$T/pshots/instructions-near.png" "abs(min(p[0] for p in $lit) - (w - 1 - max(p[0] for p in $lit))) <= 6"
check "$T/pshots/instructions-near.png" "abs(min(p[1] for p in $lit) - (h - 1 - max(p[1] for p in $lit))) <= 10"
check "$T/pshots/instructions-near.png" "max(p[0] for p in $lit) - min(p[0] for p in $lit) > 0.75 * w"
