#!/usr/bin/env bash
# The dependency arrows run one way (STYLE.md 9b): render draws into a framebuffer it is given and
# knows nothing of files, keys or windows, so nothing in src/render/ includes the io, amg or mesh
# headers, their internals, or the modules above it (scene, viewer, eval).
source "$(dirname "$0")/common.sh"

src="${ASP_TEST_SRC:?}/../src"
banned='^[[:space:]]*#[[:space:]]*include[[:space:]]*"(amgsplat/(io|amg|mesh|scene|viewer|eval|amgsplat)\.h|(io|amg|viewer|eval)/[^"]*)"'
# offenders DIR: the banned includes under DIR, one per line
offenders() { grep -rEn --include='*.c' --include='*.h' "$banned" "$1" || true; }

# the check itself must catch one coming back
mkdir -p "$T/render"
printf '#include "render/internal.h"\n#include "amgsplat/io.h"\n' >"$T/render/x.c"
printf '  #  include "amg/internal.h"\n' >"$T/render/y.h"
[[ $(offenders "$T/render" | wc -l) == 2 ]] || fail "the layer check misses planted includes"

[[ -d "$src/render" ]] || fail "no $src/render"
found=$(offenders "$src/render")
[[ -z "$found" ]] || fail "src/render/ reaches above or around its layer: $found"
echo "src/render/: no io, amg, mesh, scene, viewer or eval includes"
