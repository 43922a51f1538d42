#!/usr/bin/env python3
"""Writes the small synthetic study of tests/cli/experiment_stats.sh (docs/experiment-log.md format).

Tracks are built step by step with known grades (seed 004 2.4): along the path (+x, straight
centre line z = 0, half width 5) scores 1; backwards, perpendicular on the centre line and any
step ending out of bounds (|z| > 5) score 0. Run it from this directory: python3 make_logs.py
"""
import json
import os

PATH = [[0, 0, 0], [50, 0, 0], [100, 0, 0]]
HALF = 5.0
SUBJECTS = {  # subject: group, condition of run B
    "S01": ("control", "polygons"),
    "S02": ("control", "polygons"),
    "S03": ("variable", "points"),
    "S04": ("variable", "points"),
}
# navigation steps per subject and run: a = along, b = backwards, p = sideways (+z: perpendicular
# at the centre, then away from it),
# o = jump out of bounds then along outside; s = still (not graded)
NAV = {
    "S01": ("s" + "a" * 8 + "b" * 2, "a" * 9 + "b"),          # 80%, 90%: +10
    "S02": ("a" * 6 + "p" * 4, "a" * 8 + "p" * 2),            # 60%, 80%: +20 (B's log cut at the end)
    "S03": ("a" * 7 + "b" * 3, "a" * 5 + "o" * 5),            # 70%, 50%: -20
    "S04": ("a" * 9 + "b", "a" * 6 + "b" * 4),                # 90%, 60%: -30
}
# recognition, run B: (naming seconds, answer); run A always "cat" after 3 s
NAMING = {
    "far": {"S01": (1.0, "cat"), "S02": (1.4, "Cat "), "S03": (2.0, "cat"), "S04": (2.5, "dog")},
    "near": {"S01": (0.8, "cat"), "S02": (1.2, "cat"), "S03": (2.2, "cat"), "S04": (2.6, "cat")},
}
MS = {"polygons": 10.0, "points": 20.0}
DRAWN = {"polygons": 5000, "points": 20000}


def lcg(seed):
    while True:
        seed = (seed * 6364136223846793005 + 1442695040888963407) % 2**64
        yield (seed >> 33) / 2**31


def line(obj):
    return json.dumps(obj, separators=(",", ":")) + "\n"


def header(subject, group, test, run, cond, nav):
    h = {"type": "header", "format": "amgsplat-experiment-log 1", "subject": subject, "group": group,
         "test": test, "run": run, "condition": cond, "seed": 7, "version": "0.1.0", "observer": True,
         "screen": [320, 240], "started": "2026-11-24T14:00:00Z",
         "drawn": {"triangles": 5000, "points": 20000, "primitives": 0}}
    if nav:
        h["path"] = PATH
        h["half_width"] = HALF
    else:
        h["candidates"] = ["bunny", "cat", "horse"]
        h["answer_expected"] = "cat"
    return h


def frames(steps, cond, rnd):
    x, z, out = 10.0, 0.0, []
    pos = [(x, z)]
    for s in steps:
        if s == "a":
            x += 1
        elif s == "b":
            x -= 1
        elif s == "p":
            z += 1.0  # sideways: from the centre perpendicular, then away from it (both 0)
        elif s == "o":
            if abs(z) <= HALF:
                z = 6.0
            else:
                x += 1
        pos.append((x, z))
    for i, (px, pz) in enumerate(pos):
        ms = MS[cond] * (0.8 + 0.4 * next(rnd))
        drawn = int(DRAWN[cond] * (0.5 + next(rnd)))
        out.append({"type": "frame", "i": i, "t": round(0.05 * i, 3), "frame_ms": round(ms, 3),
                    "pos": [px, 1.7, pz], "dir": [1, 0, 0], "drawn": drawn, "keys": "W" if i else ""})
    return out


def main():
    rnd = lcg(1)
    for subject, (group, cond_b) in SUBJECTS.items():
        os.makedirs(subject, exist_ok=True)
        answers = []
        for test in ("far", "near", "lowspeed"):
            for run in ("A", "B"):
                cond = "polygons" if run == "A" else cond_b
                nav = test == "lowspeed"
                text = line(header(subject, group, test, run, cond, nav))
                if nav:
                    steps = NAV[subject][0 if run == "A" else 1]
                    for f in frames(steps, cond, rnd):
                        text += line(f)
                else:
                    naming, answer = (3.0, "cat") if run == "A" else NAMING[test][subject]
                    fr = frames("s" * 20, cond, rnd)
                    for f in fr[:10]:
                        text += line(f)
                    text += line({"type": "event", "t": 0.5, "what": "recognised", "text": ""})
                    text += line({"type": "event", "t": round(0.5 + naming, 3), "what": "answer", "text": answer})
                    for f in fr[10:]:
                        text += line(f)
                    text += line({"type": "event", "t": 1.1, "what": "end", "text": ""})
                    answers.append({"subject": subject, "test": test, "run": run, "condition": cond,
                                    "recognition_s": 0.5, "naming_s": naming, "answer": answer,
                                    "correct": answer.strip().lower() == "cat"})
                if subject == "S02" and test == "lowspeed" and run == "B":
                    # the crash: one more frame, cut off mid-line (no newline)
                    text += line({"type": "frame", "i": 99, "t": 9.9, "frame_ms": 10, "pos": [0, 1.7, 0],
                                  "dir": [1, 0, 0], "drawn": 1, "keys": "W"})[:37]
                if subject == "S03" and test == "far" and run == "A":
                    # a crash and a restart appending: a cut line glued to the next one, mid-file
                    lines = text.split("\n")
                    lines[3] = lines[3][:30] + lines[4]
                    del lines[4]
                    text = "\n".join(lines)
                with open(f"{subject}/{test}-{run}.jsonl", "w") as fp:
                    fp.write(text)
        with open(f"{subject}/answers.jsonl", "w") as fp:
            for a in answers:
                fp.write(line(a))
    with open("study.json", "w") as fp:
        json.dump({"format": "amgsplat-study 1", "seed": 7, "version": "0.1.0", "subjects": list(SUBJECTS),
                   "tests": ["far", "near", "lowspeed"], "conditions": ["polygons", "points"], "observer": True,
                   "scenes": {}}, fp)
        fp.write("\n")


if __name__ == "__main__":
    main()
