#!/usr/bin/env bash
# The README's test command: installs dependencies, builds, and runs every
# test twice — an optimised build, then an ASan+UBSan build.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/bootstrap.sh
jobs=$(nproc)

cmake -S . -B build -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build build -j "$jobs"
(cd build && ctest --output-on-failure -j "$jobs")

cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Debug -DASP_SANITIZE=ON -DASP_BUILD_BENCH=OFF >/dev/null
cmake --build build-asan -j "$jobs"
# tests that start MPI get full unwinding from CMakeLists.txt (see there)
# intercept_tls_get_addr=0: GCC 12's LeakSanitizer on glibc 2.36 reads a bogus dynamic-TLS range
# ("DTLS 16 at 0xdbf-0x1800001ec1") and its tracer dies of SIGSEGV at exit once Mesa and GLFW are
# loaded (amgsplat view FILE.dps under Xvfb, every run); without the interception it does not
export ASAN_OPTIONS="detect_leaks=1:strict_string_checks=1:intercept_tls_get_addr=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp:print_suppressions=0"
(cd build-asan && ctest --output-on-failure -j "$jobs")
