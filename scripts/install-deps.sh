#!/usr/bin/env bash
# Installs the Debian packages renderlab needs, and only those that are missing.
# Idempotent: with everything present it touches nothing and asks no network.
set -euo pipefail

PACKAGES=(
  build-essential cmake pkg-config
  libpng-dev          # PNG output
  libopenexr-dev      # EXR output
  libstb-dev          # PNG/JPEG texture input (stb_image)
  libcjson-dev        # scene and result files
  libassimp-dev       # OBJ, PLY, STL, glTF, DAE, 3DS, FBX import
  libembree-dev       # Embree 3: reference accelerator and benchmark anchor
  libepoxy-dev libegl-dev            # OpenGL 4.5 backend (src/gl): GL loader, EGL headers
  libegl-mesa0 libgl1-mesa-dri       # headless EGL + llvmpipe, so the GL tests run without a GPU
  libopenmpi-dev openmpi-bin         # distributed runs (src/dist, rl --dist under mpirun)
  libcmocka-dev       # unit tests
  libcairo2-dev       # plots in evaluation reports (SVG, PNG)
  libsdl2-dev         # rl view: the interactive viewer's window
  xvfb xauth          # xvfb-run: the viewer's tests without a display
  fonts-dejavu-core   # a font for plot labels
  assimp-testmodels   # real meshes for rl bench rays
  python3             # the JSON checks of the CLI tests
  time                # /usr/bin/time: peak memory of the hostile-input tests
  clang libclang-rt-dev libomp-dev   # the libFuzzer harnesses (tests/fuzz)
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
    echo "deps: missing ${missing[*]} and not root (no sudo available)" >&2; exit 1
  fi
fi
echo "deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
