#!/usr/bin/env bash
# Installs what Micropoly needs on Debian 12, builds it, and then
#   demo: renders the demo scene through headless Blender to demo.png
#         (and the Utah teapot RIB through micropoly-render to teapot.png)
#   test: runs every test (ctest: GoogleTest, pytest, Blender tests), then
#         the sanitized build's tests and the fuzz targets' short runs
#         (scripts/check_sanitized.sh, docs/reliability.md)
#   build: stops after building (and installing into build/install)
# Usage: scripts/setup.sh [demo|test|build]   (as root, or through sudo)
set -euo pipefail
mode=${1:-build}
here=$(cd "$(dirname "$0")/.." && pwd)
cd "$here"

packages=(
  build-essential cmake pkg-config git
  ocl-icd-opencl-dev opencl-headers pocl-opencl-icd clinfo
  libglm-dev pybind11-dev libosd-dev libgtest-dev libgmock-dev
  libpng-dev libopenexr-dev
  python3 python3-dev python3-numpy python3-pytest python3-venv python3-pil util-linux
  clang libclang-rt-14-dev llvm
  blender xvfb xauth libgl1-mesa-dri
  qemu-user
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  echo "== installing: ${missing[*]}"
  $sudo apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# Blender as a Python module (the bpy wheels): the newest release whose wheel
# installs for this Python, and the 4.x LTS. Only the tests need them.
BPY_VERSIONS=${MICROPOLY_BPY_VERSIONS:-"4.5.15 5.0.1"}
if [ "$mode" = test ]; then
  mkdir -p build
  for v in $BPY_VERSIONS; do
    venv="build/bpy-$v"
    if ! "$venv/bin/python3" -c "import bpy" >/dev/null 2>&1; then
      echo "== installing the bpy $v module into $venv"
      rm -rf "$venv"
      /usr/bin/python3 -m venv "$venv"
      "$venv/bin/python3" -m pip install -q --disable-pip-version-check "bpy==$v" ||
        { echo "bpy $v did not install" >&2; rm -rf "$venv"; exit 1; }
    fi
  done
  # openjd-cli runs the farm job template locally (tests/farm/test_openjd.py).
  if ! build/openjd-venv/bin/openjd --version >/dev/null 2>&1; then
    echo "== installing openjd-cli into build/openjd-venv"
    rm -rf build/openjd-venv
    /usr/bin/python3 -m venv build/openjd-venv
    build/openjd-venv/bin/python3 -m pip install -q --disable-pip-version-check \
      "openjd-cli==0.8.0" "openjd-model==0.13.0" "openjd-sessions==0.13.0" ||
      { echo "openjd-cli did not install" >&2; rm -rf build/openjd-venv; exit 1; }
  fi
fi

jobs=$(nproc)
echo "== building"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DPython_EXECUTABLE=/usr/bin/python3 >/dev/null
cmake --build build -j "$jobs"
cmake --install build --prefix build/install >/dev/null

case "$mode" in
  build) ;;
  demo)
    echo "== rendering the demo scene through headless Blender"
    rm -f demo.png
    BLENDER_USER_SCRIPTS="$here/build/install" blender -b --factory-startup --python-exit-code 1 \
      --python scripts/build/demo_scene.py -- "$here/demo.png" 2>&1 | grep -E "wrote|Error|error" || true
    [ -s demo.png ] || { echo "the demo render failed" >&2; exit 1; }
    echo "== and the Utah teapot through the command line renderer"
    build/install/bin/micropoly-render tests/scenes/teapot.rib -o teapot.png --spp 16 --stats teapot-stats.json
    echo "wrote $here/demo.png and $here/teapot.png"
    ;;
  test)
    echo "== running tests"
    # One test per core: much of a test is single-threaded (Blender's start,
    # the export, kernel builds), so two at a time finish sooner.
    (cd build && ctest --output-on-failure -j "$jobs")
    echo "== sanitizers (AddressSanitizer, UndefinedBehaviorSanitizer) and fuzzing"
    bash scripts/check_sanitized.sh build-sanitize
    ;;
  *) echo "unknown mode '$mode' (demo, test or build)" >&2; exit 2 ;;
esac
