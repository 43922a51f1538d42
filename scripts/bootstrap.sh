#!/usr/bin/env bash
# Installs every build, test and demo dependency from Debian packages (apt-get
# only). Idempotent: installs nothing when everything is already present.
# Usage: scripts/bootstrap.sh [--bench]   (--fuzz is still accepted; clang is always installed now,
# since scripts/test.sh compiles once with clang and runs the libFuzzer targets)
#   --bench  also the benchmark-only peers that no build or test needs: python3-open3d (screened
#            Poisson for bench/bench_fit.sh; large, so the README's two commands leave it out)
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libhypre-dev libopenmpi-dev      # BoomerAMG (hypre) on MPI
  libepoxy-dev libegl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri   # OpenGL 4.5 core via EGL (Mesa llvmpipe headless)
  libglfw3-dev                     # viewer windows
  libassimp-dev                    # mesh formats
  libmeshoptimizer-dev             # simplified meshes (amgsplat simplify; 0.18 in Debian 12)
  libsquish-dev                    # BC1/BC3 (S3TC) compression of the fitted atlases (issue 27)
  libstb-dev                       # PNG/JPEG read and write
  zlib1g-dev                       # CRC-32 of the .amg and .dps files
  libflann-dev                     # k-NN baseline for bench/bench_knn.c
  xvfb xauth                       # viewer test under a virtual display
  glmark2-data                     # ships the Stanford bunny (demo model)
  clang libclang-rt-14-dev         # the clang build and the libFuzzer targets (scripts/test.sh)
  python3                          # tests/cli/png_check.py and the JSON checks of tests/cli
  libcjson-dev                     # the one JSON library (reading and writing)
  libgsl-dev                       # statistics of the perceptual experiment (t distribution)
  libplplot-dev plplot-driver-cairo fonts-dejavu-core   # charts (PLplot, drawn in memory by its cairo driver) and their font
  chromium                         # the web page's test in headless Chromium (puppeteer-core)
)
# Node.js and npm for the web page and its tests (three.js, 3d-tiles-renderer, cesium, gltf-validator,
# puppeteer-core, loaders.gl, pinned in web/package-lock.json). Debian's packages when no node is on the PATH; a node that is
# already installed (another distribution of it) is kept, since Debian's npm would conflict with it.
if ! command -v npm >/dev/null 2>&1; then
  packages+=(nodejs npm)
fi

for arg in "$@"; do
  case "$arg" in
  --bench) packages+=(python3-open3d) ;; # screened Poisson + quadric decimation peer of bench/bench_fit.sh
  --fuzz) ;;
  *) echo "bootstrap: unknown option '$arg' (expected --bench)" >&2; exit 2 ;;
  esac
done

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

# npm packages from the lock file, when they are missing or the lock file changed since (idempotent).
npm_ci() {
  local root
  root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
  if [[ ! -f "$root/web/node_modules/.package-lock.json" || "$root/web/package-lock.json" -nt "$root/web/node_modules/.package-lock.json" ]]; then
    echo "bootstrap: npm ci in web/ (packages pinned in web/package-lock.json)" >&2
    (cd "$root/web" && npm ci --no-audit --no-fund --loglevel=error >/dev/null)
  fi
}

if ((${#missing[@]} == 0)); then
  npm_ci
  exit 0
fi

SUDO=""
if [[ $(id -u) -ne 0 ]]; then
  SUDO="sudo"
fi
echo "bootstrap: installing ${missing[*]}" >&2
$SUDO env DEBIAN_FRONTEND=noninteractive apt-get update -qq
$SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
npm_ci
