# One vocabulary across commands (issue 29): every command's -h is parsed, and an option for the
# same concept has one name everywhere (output -o/--output, --tolerance, --color-by, --level,
# --method, --renderer, --threads, --quiet, --json); the old spellings --tau (screen tolerance)
# and --color survive only as documented deprecated aliases that say so on stderr when used.
source "$(dirname "$0")/common.sh"
A=$AMGSPLAT
cmds=$("$A" help | awk '/^commands:/{f=1;next} f&&/^ /{print $1} f&&/^$/{exit}')
[[ $(echo $cmds | wc -w) -ge 15 ]] || fail "too few commands listed: $cmds"
# scene and experiment dispatch to subcommands, whose -h lists the options
for c in $cmds; do
  case $c in scene | experiment) continue ;; esac
  "$A" "$c" -h >"$T/$c.h" || fail "$c -h"
done
"$A" scene field -h >"$T/scene.h" || fail "scene field -h"
for sub in run analyze ttest; do
  "$A" experiment $sub -h >"$T/experiment-$sub.h" || fail "experiment $sub -h"
done
python3 - "$T" $cmds <<'EOF' || fail "vocabulary check failed (see above)"
import glob, os, re, sys
T, cmds = sys.argv[1], sys.argv[2:]
# each concept: the one name, and spellings another command might have used for it
concepts = {
    "output": ("output", {"out", "outfile", "output-file", "dest", "dst", "out-file"}),
    "tolerance": ("tolerance", {"tol", "tau-px", "screen-tolerance", "pixel-tolerance"}),
    "colour mode": ("color-by", {"colour-by", "colour", "color-mode", "colour-mode", "colorby"}),
    "level": ("level", {"lvl", "amg-level", "lod"}),
    "method": ("method", {"blend", "blend-method", "blending"}),
    "renderer": ("renderer", {"render-mode", "draw", "drawer", "render"}),
    "threads": ("threads", {"jobs", "nthreads", "num-threads", "j"}),
    "quiet": ("quiet", {"silent", "no-progress"}),
    "json": ("json", {"json-out", "machine"}),
}
# the deprecated aliases: name -> (the name it stands for, words its help must hold)
aliases = {"tau": ("tolerance", "deprecated spelling of --tolerance"),
           "color": ("color-by", "deprecated spelling of --color-by")}
opt_re = re.compile(r"^  (?:-(\w), )?\s*--([a-z0-9-]+)(?: (\S+))?\s+(.*)$")
bad, seen = [], {}
files = sorted(glob.glob(os.path.join(T, "*.h")))
assert len(files) >= len(cmds) + 2, files
for f in files:
    cmd = os.path.basename(f)[:-2]
    text = open(f).read()
    if "\noptions:\n" not in text:
        bad.append(f"{cmd}: no options section"); continue
    opts = {}
    for line in text.split("\noptions:\n", 1)[1].splitlines():
        m = opt_re.match(line)
        if m:
            opts[m.group(2)] = (m.group(1), m.group(4))
    seen[cmd] = opts
    for must in ("quiet", "json", "threads", "help"):
        if must not in opts:
            bad.append(f"{cmd}: no --{must}")
    if opts.get("quiet", ("q",))[0] != "q":
        bad.append(f"{cmd}: --quiet is not -q")
    for concept, (name, others) in concepts.items():
        for o in others & set(opts):
            bad.append(f"{cmd}: --{o} for the {concept}; the name is --{name}")
    if "output" in opts and opts["output"][0] != "o":
        bad.append(f"{cmd}: --output without -o")
    for o, (sn, help_) in opts.items():
        if sn == "o" and o != "output":
            bad.append(f"{cmd}: -o is --{o}, not --output")
        # an option described as the output file/directory is -o/--output
        if o != "output" and re.match(r"(output|write[s]? to) (file|png|directory|point file)", help_, re.I):
            bad.append(f"{cmd}: --{o} ({help_}) is an output; the name is -o/--output")
        if "screen tolerance" in help_ and o != "tolerance":
            bad.append(f"{cmd}: --{o} is the screen tolerance; the name is --tolerance")
        if o in aliases:
            target, words = aliases[o]
            # build/decompose --tau is a different concept (the domain threshold Psi > tau, thesis 2.3)
            if o == "tau" and "domain threshold" in help_:
                continue
            if words not in help_:
                bad.append(f"{cmd}: --{o} is neither '{words}' nor another documented concept: {help_}")
            if target not in opts:
                bad.append(f"{cmd}: deprecated --{o} without --{target}")
# the commands that write a file name it with -o (info, imgdiff, view, bench-paper and ttest print)
for cmd in ("convert", "sample", "synth", "estimate", "render", "decompose", "simplify", "build", "fit",
            "export", "scene", "eval", "experiment-run", "experiment-analyze"):
    if "output" not in seen.get(cmd, {}):
        bad.append(f"{cmd}: writes a file but has no -o/--output")
for cmd in ("render", "view"):
    for o in ("tolerance", "color-by", "level", "method", "renderer"):
        if o not in seen.get(cmd, {}):
            bad.append(f"{cmd}: no --{o}")
for b in bad:
    print("vocabulary:", b, file=sys.stderr)
sys.exit(1 if bad else 0)
EOF

# convert takes -o like every other command, and IN OUT as before; the two give the same file
"$A" synth octahedron -n 200 -o "$T/o.ply" -q
"$A" convert "$T/o.ply" -o "$T/a.xyz" -q
"$A" convert "$T/o.ply" "$T/b.xyz" -q
cmp -s "$T/a.xyz" "$T/b.xyz" || fail "convert IN -o OUT and convert IN OUT differ"
expect_fail 2 "with -o $T/c.xyz expected one input file, got 2" "$A" convert "$T/o.ply" "$T/b.xyz" -o "$T/c.xyz"

# the old spellings work, say once that they are deprecated, and keep quiet under --quiet
"$A" render "$T/o.ply" -o "$T/t.png" --size 16x16 --tau 2 2>"$T/tau.err" >/dev/null
grep -qF "amgsplat render: --tau is deprecated; use --tolerance" "$T/tau.err" || fail "no note for --tau: $(cat "$T/tau.err")"
[[ $(grep -c deprecated "$T/tau.err") -eq 1 ]] || fail "note for --tau not once: $(cat "$T/tau.err")"
"$A" render "$T/o.ply" -o "$T/t.png" --size 16x16 --tau 2 -q 2>"$T/tauq.err" >/dev/null
! grep -q deprecated "$T/tauq.err" || fail "--quiet still prints the note: $(cat "$T/tauq.err")"
"$A" render "$T/o.ply" -o "$T/t.png" --size 16x16 --tolerance 2 2>"$T/tol.err" >/dev/null
! grep -q deprecated "$T/tol.err" || fail "--tolerance called deprecated: $(cat "$T/tol.err")"
expect_fail 2 "amgsplat view: --color is deprecated; use --color-by" "$A" view "$T/o.ply" --color rainbow

# the overview says what each command reads
"$A" help >"$T/overview"
grep -q "^what each command reads:" "$T/overview" || fail "overview lacks the inputs section"
for c in $cmds; do
  awk -v c="$c" '/^what each command reads:/{f=1;next} f&&$1==c{print; found=1} END{exit !found}' "$T/overview" \
    >/dev/null || fail "overview: no inputs for $c"
done
grep -E "^  convert +.*LAS" "$T/overview" >/dev/null || fail "convert's inputs lack LAS"
grep -E "^  info +.*meshes.*\.amg.*\.dps.*\.hier" "$T/overview" >/dev/null || fail "info's inputs lack meshes/.amg/.dps/.hier"
echo "vocabulary: $(echo $cmds | wc -w) commands + 3 experiment subcommands checked"
