#!/usr/bin/env bash
# The README's test command and CI's (.ci/run calls it): installs dependencies, then builds and
# tests every configuration with -Werror (ASP_WERROR is off for users; docs/build.md):
#   a. RelWithDebInfo (gcc)          build/          all targets, ctest
#   b. Release -O3 (gcc)             build-release/  all targets, ctest but the e2e label
#   c. Release with clang, libFuzzer + ASan/UBSan    build-fuzz/  all targets and tools/fuzz_*.c
#   d. reduced: no GL, no hypre      build-nogl/ build-nohypre/  library + its tests, ctest
#   e. fuzz smoke: every fuzz target of c, FUZZ_SECONDS each, seeded from files made by a
#   f. ASan + UBSan (gcc, Debug)     build-asan/     ctest but the e2e label
# Stops at the first failure. Prints each stage's time and test counts; docs/build.md lists
# measured times. Build directories are reused, so a second run only rebuilds what changed.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/bootstrap.sh
jobs=$(nproc)
fuzz_seconds=${FUZZ_SECONDS:-10}
werror=(-DASP_WERROR=ON)
summary=()
t_all=$SECONDS
n_passed=0 n_failed=0 n_skipped=0 # over every ctest run, for the closing line

# stage NAME CMD...: runs CMD, records its wall time
stage() {
  local name=$1 t0=$SECONDS idx=${#summary[@]}
  shift
  echo "=== $name" >&2
  summary+=("$name: failed")
  "$@"
  summary[idx]=$(printf '%-34s %5ds' "$name" $((SECONDS - t0)))
}

# configure DIR ARGS...: (re)configures DIR with -Werror
configure() {
  local dir=$1
  shift
  cmake -S . -B "$dir" "${werror[@]}" "$@" >/dev/null
}

# run_ctest DIR [CTEST ARGS...]: ctest in DIR; appends "passed/failed/skipped" to the summary
run_ctest() {
  local dir=$1 log
  shift
  log=$(mktemp)
  local st=0
  (cd "$dir" && ctest --output-on-failure -j "$jobs" "$@") 2>&1 | tee "$log" || st=$?
  local total skipped failed
  total=$(grep -Eo 'out of [0-9]+' "$log" | tail -1 | grep -Eo '[0-9]+' || echo 0)
  skipped=$(grep -c '\*\*\*Skipped\|Not Run' "$log" || true)
  failed=$(grep -Eo '[0-9]+ tests failed' "$log" | tail -1 | grep -Eo '^[0-9]+' || echo "?")
  rm -f "$log"
  n_passed=$((n_passed + total - skipped - ${failed/\?/0}))
  n_failed=$((n_failed + ${failed/\?/1}))
  n_skipped=$((n_skipped + skipped))
  summary+=("  $dir${*:+ ($*)}: $total tests, $((total - skipped - ${failed/\?/0})) passed, $failed failed, $skipped skipped")
  return "$st"
}

build_a() {
  configure build -DCMAKE_BUILD_TYPE=RelWithDebInfo
  cmake --build build -j "$jobs"
  scripts/check_declared.py build/libamgsplat.a
  run_ctest build
}

build_b() {
  configure build-release -DCMAKE_BUILD_TYPE=Release
  cmake --build build-release -j "$jobs"
  # the end-to-end tests (label e2e: browser, Xvfb, whole experiment) ran in stage a
  run_ctest build-release -LE e2e
}

# One clang compile of everything (library, CLI, tests, benchmarks, fuzzers); its tests are not
# run: the ASan build (f) runs them instrumented, a and b uninstrumented.
build_c() {
  CC=clang configure build-fuzz -DCMAKE_BUILD_TYPE=Release -DASP_FUZZ=ON
  cmake --build build-fuzz -j "$jobs"
}

# The reduced builds compile the library and the tests that apply, and check that every function
# the built modules' headers declare is defined (scripts/check_declared.py): a test only links
# against what it calls.
build_d() {
  configure build-nogl -DCMAKE_BUILD_TYPE=RelWithDebInfo -DASP_WITH_GL=OFF -DASP_BUILD_BENCH=OFF
  cmake --build build-nogl -j "$jobs"
  # the modules this build leaves out whole (GL): their headers declare what it lacks
  scripts/check_declared.py build-nogl/libamgsplat.a render.h viewer.h experiment.h scene_renderer.h
  run_ctest build-nogl
  configure build-nohypre -DCMAKE_BUILD_TYPE=RelWithDebInfo -DASP_WITH_HYPRE=OFF -DASP_BUILD_BENCH=OFF
  cmake --build build-nohypre -j "$jobs"
  scripts/check_declared.py build-nohypre/libamgsplat.a
  run_ctest build-nohypre
}

# Seeds: the committed corpus of each target (tools/corpus/<target>/, remade by
# tools/corpus/make_seeds.py or replaced by the minimized corpora of longer runs), small valid files
# of every format the fuzzers read made fresh by build a's tools (the current format versions), and
# the malformed inputs of tests/data/bad.
fuzz_smoke() {
  local seeds=build-fuzz/seeds
  rm -rf "$seeds" build-fuzz/corpus
  mkdir -p "$seeds"
  local A=build/amgsplat
  "$A" synth octahedron --points 400 -o "$seeds/oct.ply" -q
  "$A" convert "$seeds/oct.ply" "$seeds/oct.xyz"
  "$A" convert --ascii "$seeds/oct.ply" "$seeds/oct_ascii.ply"
  "$A" convert --big-endian "$seeds/oct.ply" "$seeds/oct_be.ply"
  "$A" decompose "$seeds/oct.ply" -o "$seeds/oct.amg" -q
  "$A" build "$seeds/oct.amg" -o "$seeds/oct.dps" --primitives 8 -q >/dev/null
  build/seed_hier "$seeds/oct.ply" "$seeds/oct.hier"
  "$A" convert "$seeds/oct.ply" -o "$seeds/oct_streamed.hier" --memory 64M --node-points 64 -q
  "$A" render "$seeds/oct.ply" -o "$seeds/oct.png" --size 32x32 -q
  "$A" convert "$seeds/oct.ply" "$seeds/oct.las" -q
  "$A" convert --las-format 3 "$seeds/oct.ply" "$seeds/oct3.las" -q
  python3 tests/cli/las_handmade.py "$seeds/hand14.las" 4 8 20 --extra >/dev/null
  python3 tests/cli/las_handmade.py "$seeds/hand12.las" 2 1 20 >/dev/null
  # seeds: regular files only, from files and folders (tests/data/bad has subfolders per kind)
  seed() {
    local dst=$1
    shift
    find "$@" -type f -exec cp --backup=numbered -t "$dst" {} +   # same names in two folders: both kept
  }
  local f name corpus
  for f in build-fuzz/fuzz_*; do
    [[ -x $f && -f $f ]] || continue
    name=$(basename "$f")
    corpus=build-fuzz/corpus/$name
    mkdir -p "$corpus"
    case $name in
      fuzz_ply) seed "$corpus" "$seeds"/*.ply "$seeds"/*.xyz tests/data/bad ;;
      fuzz_xyz) seed "$corpus" "$seeds"/*.xyz tests/data/bad ;;
      fuzz_amg) seed "$corpus" "$seeds"/*.amg ;;
      fuzz_dps) seed "$corpus" "$seeds"/*.dps ;;
      fuzz_hier) seed "$corpus" "$seeds"/*.hier ;;
      fuzz_image) seed "$corpus" "$seeds"/*.png tests/data/bad/image ;;
      fuzz_mesh) seed "$corpus" "$seeds"/*.ply tests/data/bad/mesh ;;
      fuzz_gltf) seed "$corpus" tests/data/bad/assimp/*.gltf tests/data/bad/assimp/*.glb ;;
      fuzz_collada) seed "$corpus" tests/data/bad/assimp/*.dae ;;
      fuzz_las) seed "$corpus" "$seeds"/*.las ;;
      fuzz_point_stream) seed "$corpus" "$seeds"/*.ply "$seeds"/*.las ;;
      fuzz_ooc) seed "$corpus" "$seeds"/*.hier ;;
      fuzz_stats_log) seed "$corpus" tests/data/experiment ;;
      fuzz_scene_file) : ;; # JSON only: its committed corpus below
      *) seed "$corpus" "$seeds" tests/data/bad ;; # a new target: every format as a start
    esac
    if [[ -d tools/corpus/$name ]]; then
      seed "$corpus" "tools/corpus/$name"
    fi
    local nseeds
    nseeds=$(ls "$corpus" | wc -l)
    echo "--- $name: $fuzz_seconds s" >&2
    # leaks are checked: the readers start no MPI. -max_len keeps mutations near the seeds' sizes.
    local log=build-fuzz/$name.log st=0
    local asan="detect_leaks=1:strict_string_checks=1" lsan=""
    if [[ $name == fuzz_mesh ]]; then # assimp's own leaks and strtol calls: the two .supp files say why
      asan+=":fast_unwind_on_malloc=0:suppressions=$PWD/tools/fuzz_mesh_asan.supp"
      lsan="suppressions=$PWD/tools/fuzz_mesh.supp:print_suppressions=0"
    fi
    ASAN_OPTIONS="$asan" LSAN_OPTIONS="$lsan" UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
      "$f" -max_total_time="$fuzz_seconds" -rss_limit_mb=2048 -max_len=65536 -print_final_stats=1 \
      -artifact_prefix=build-fuzz/"$name"- "$corpus" >"$log" 2>&1 || st=$?
    if ((st != 0)); then
      tail -n 60 "$log" >&2
      echo "$name: exit status $st; the failing input is build-fuzz/$name-*" >&2
      return 1
    fi
    local runs
    runs=$(grep -Eo 'stat::number_of_executed_units: *[0-9]+' "$log" | grep -Eo '[0-9]+$' || echo "?")
    summary+=("  $name: $runs inputs in ${fuzz_seconds}s from $nseeds seeds, corpus now $(ls "$corpus" | wc -l), no failure")
  done
}

build_f() {
  configure build-asan -DCMAKE_BUILD_TYPE=Debug -DASP_SANITIZE=ON -DASP_BUILD_BENCH=OFF
  cmake --build build-asan -j "$jobs"
  # tests that start MPI get full unwinding from CMakeLists.txt (see there)
  # intercept_tls_get_addr=0: GCC 12's LeakSanitizer on glibc 2.36 reads a bogus dynamic-TLS range
  # ("DTLS 16 at 0xdbf-0x1800001ec1") and its tracer dies of SIGSEGV at exit once Mesa and GLFW are
  # loaded (amgsplat view FILE.dps under Xvfb, every run); without the interception it does not
  ASAN_OPTIONS="detect_leaks=1:strict_string_checks=1:intercept_tls_get_addr=0" \
    UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
    LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp:print_suppressions=0" \
    run_ctest build-asan -LE e2e
}

report() {
  echo "=== summary (wall time per stage)" >&2
  printf '%s\n' "${summary[@]}" >&2
  printf '%-34s %5ds\n' "total" $((SECONDS - t_all)) >&2
  # the plain closing line CI reads: every ctest run added up; a stage that failed outside ctest
  # (a build, a fuzz target) counts as one failure, so the line never reads "0 failed" on a failure
  local s
  for s in "${summary[@]}"; do
    [[ $s == *": failed" ]] && n_failed=$((n_failed + 1))
  done
  echo "tests: $n_passed passed, $n_failed failed, $n_skipped skipped"
}
trap report EXIT

stage "a. RelWithDebInfo build + ctest" build_a
stage "b. Release -O3 build + ctest" build_b
stage "c. clang + libFuzzer build" build_c
stage "d. no-GL, no-hypre builds + ctest" build_d
stage "e. fuzz smoke" fuzz_smoke
stage "f. ASan+UBSan build + ctest" build_f
