#!/usr/bin/env bash
# The dependency arrows run one way (STYLE.md 9b): render draws into a framebuffer it is given and
# knows nothing of files, keys or windows, so nothing in src/render/ includes the io, amg or mesh
# headers, their internals, or the modules above it (scene, instances, viewer, eval, experiment);
# and render's public headers (render*.h, scene_renderer.h) include only render's own headers and
# those of the modules below it that render draws from (core, cloud, image, hier, prim, camera),
# never eval (scene.h, instances.h, eval.h), io (io.h, mesh.h) or amg (amg.h) headers. camera.h,
# the GL-free camera render and eval share, includes core headers only. And no file in src/render
# compares another kind's renderer table: callers call the table's entries (STYLE.md 9b).
source "$(dirname "$0")/common.sh"

src="${ASP_TEST_SRC:?}/../src"
inc="${ASP_TEST_SRC:?}/../include/amgsplat"
banned='^[[:space:]]*#[[:space:]]*include[[:space:]]*"(amgsplat/(io|amg|amg_distributed|mesh|scene|instances|viewer|eval|experiment|amgsplat)\.h|(io|amg|viewer|eval|experiment)/[^"]*)"'
# offenders DIR: the banned includes under DIR, one per line
offenders() { grep -rEn --include='*.c' --include='*.h' "$banned" "$1" || true; }

# header_offenders ALLOWED FILE...: each #include "x.h" of FILE whose name is not in ALLOWED (a
# space-separated list), as FILE:LINE: x.h
header_offenders() {
  local allowed=" $1 " f n line h
  shift
  for f in "$@"; do
    n=0
    while IFS= read -r line; do
      n=$((n + 1))
      [[ $line =~ ^[[:space:]]*#[[:space:]]*include[[:space:]]*\"([^\"]+)\" ]] || continue
      h=${BASH_REMATCH[1]#amgsplat/}
      [[ $allowed == *" $h "* ]] || echo "$(basename "$f"):$n: $h"
    done <"$f"
  done
}
render_allowed="render.h scene_renderer.h core.h cloud.h image.h hier.h prim.h camera.h"
camera_allowed="core.h cloud.h"

# table_offenders FILE...: tables a file compares (vt == &x / vt != &x) that are not its own static
# table: the public calls dispatch through the table's entries instead (STYLE.md 9b, renderer.c),
# and only a kind's own calls check that a handle is theirs
table_offenders() {
  local f t
  for f in "$@"; do
    for t in $(grep -oE 'vt[[:space:]]*[!=]=[[:space:]]*&[A-Za-z_0-9]+' "$f" | sed 's/.*&//' | sort -u); do
      grep -E "^static const asp__renderer_vtable $t( =|;)" "$f" >/dev/null || echo "$(basename "$f"): $t"
    done
  done
}

# the checks themselves must catch a violation coming back
mkdir -p "$T/render" "$T/include"
printf '#include "render/internal.h"\n#include "amgsplat/io.h"\n' >"$T/render/x.c"
printf '  #  include "amg/internal.h"\n#include "amgsplat/instances.h"\n' >"$T/render/y.h"
[[ $(offenders "$T/render" | wc -l) == 3 ]] || fail "the layer check misses planted includes in src/render"
printf '#include "camera.h"\n#include "prim.h"\n#include "instances.h"\n' >"$T/include/scene_renderer.h"
printf '#include "render.h"\n  # include "amgsplat/mesh.h"\n#include "eval.h"\n#include "amg.h"\n' \
  >"$T/include/render_x.h"
planted=$(header_offenders "$render_allowed" "$T/include/scene_renderer.h" "$T/include/render_x.h")
[[ $planted == $'scene_renderer.h:3: instances.h\nrender_x.h:2: mesh.h\nrender_x.h:3: eval.h\nrender_x.h:4: amg.h' ]] ||
  fail "the render header check misses planted includes: $planted"

printf 'static const asp__renderer_vtable own_vtable;\nint f(asp_renderer *r) { return r->vt == &own_vtable || r->vt != &asp__other_vtable; }\n' \
  >"$T/render/z.c"
[[ $(table_offenders "$T/render/z.c") == "z.c: asp__other_vtable" ]] || fail "the table check misses a planted comparison"

[[ -d "$src/render" ]] || fail "no $src/render"
found=$(offenders "$src/render")
[[ -z "$found" ]] || fail "src/render/ reaches above or around its layer: $found"
echo "src/render/: no io, amg, mesh, scene, instances, viewer, eval or experiment includes"
found=$(table_offenders "$src"/render/*.c)
[[ -z "$found" ]] || fail "src/render/ compares another kind's renderer table instead of calling its entries: $found"
echo "src/render/: every table comparison is a kind checking its own handle"

headers=("$inc"/render*.h "$inc/scene_renderer.h")
for h in "${headers[@]}"; do [[ -r $h ]] || fail "no render header $h"; done
found=$(header_offenders "$render_allowed" "${headers[@]}")
[[ -z "$found" ]] || fail "a render header includes a header above or around render (eval, io, amg): $found"
found=$(header_offenders "$camera_allowed" "$inc/camera.h")
[[ -z "$found" ]] || fail "camera.h (GL-free, below render) includes more than core: $found"
echo "render headers ($(cd "$inc" && echo render*.h scene_renderer.h)): only render, core, cloud, image, hier, prim and camera headers"
