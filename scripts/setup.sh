#!/usr/bin/env bash
# One-command set-up for apparent on Debian 12 (README "Set up").
#   scripts/setup.sh demo   install packages, build the program only, render the default scene into out/
#   scripts/setup.sh test   install packages (and the npm validators), build, run the whole test suite
#   scripts/setup.sh build  install packages and build everything, nothing run
# Environment: BUILD_DIR (default build), JOBS (default: number of cores), SKIP_APT=1 to skip apt-get.
set -euo pipefail

mode=${1:-demo}
case "$mode" in demo|test|build) ;; *) echo "usage: $0 demo|test|build" >&2; exit 2 ;; esac

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
build_dir=${BUILD_DIR:-build}
jobs=${JOBS:-$(nproc)}

# Step: Debian packages (docs/DEPENDENCIES.md section 1). assimp-testmodels holds real
# third-party meshes for import tests; nodejs/npm run the Khronos glTF-Validator.
packages=(build-essential cmake pkg-config
  libopenmesh-dev libcgal-dev libtinygltf-dev libdraco-dev draco nlohmann-json3-dev libeigen3-dev
  libcli11-dev libtbb-dev libgtest-dev libgmock-dev libbenchmark-dev assimp-testmodels libpng-dev
  libmeshoptimizer-dev  # EXT_meshopt_compression in the .glb (--compress meshopt)
  gnuplot-nox gltfpack  # gltfpack: the peer of benchmarks/load_bench; gnuplot draws `apparent trade`'s plot (DIR/trade.png) and docs/accuracy.png
  valgrind  # callgrind counts the refinement's instructions per output triangle (scripts/accuracy_report.sh)
  libfreetype-dev fonts-dejavu-core ffmpeg)  # figure labels; raytrace/figure --video (and ffprobe in the tests)
packages+=(libopenmpi-dev openmpi-bin)  # mpirun -n N apparent render (optional in CMake; the mpi_ranks test needs it)
packages+=(python3 bc)  # scripts/*_report.sh run Python helpers; mpi_report.sh and measure_gltf_sizes.sh compute ratios with bc
packages+=(pybind11-dev python3-pybind11 python3-numpy python3-venv python3-pip)  # `import apparent` (python/, docs/PYTHON.md); venv and pip: its install
if [ "$mode" = test ]; then
  packages+=(chromium)            # three.js viewer test (tests/web), headless
  packages+=(meshlab xvfb xauth)  # MeshLab opens the PLY output (tests/validators/meshlab_ply.sh)
  packages+=(blender python3-numpy)  # Blender imports the .glb (tests/blender); its importer needs numpy
  packages+=(python3 clang-14 libclang-rt-14-dev)  # kill test (tests/kill_test.py); libFuzzer for scripts/fuzz.sh
  packages+=(gltfpack assimp-utils)  # scripts/measure_gltf_sizes.sh: gltfpack -cc beside our codecs; the Duck as OBJ
  packages+=(python3-pytest)  # ctest python_module runs python/tests
  packages+=(jupyter-nbconvert python3-ipykernel python3-matplotlib)  # ctest python_notebooks executes examples/*.ipynb
  packages+=(git)  # ctest repository_stands_alone reads the tracked files (tests/repository/stands_alone.sh)
  packages+=(emscripten)  # ctest wasm_parity: mesh4d/ compiled to WebAssembly, against the native build (tests/wasm)
  command -v node >/dev/null 2>&1 || packages+=(nodejs)
  command -v npm >/dev/null 2>&1 || packages+=(npm)
fi
if [ "${SKIP_APT:-0}" != 1 ]; then
  missing=()
  for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -gt 0 ]; then
    sudo=""
    [ "$(id -u)" -ne 0 ] && sudo=sudo
    echo "== installing ${missing[*]}"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  fi
fi

# Step: npm validators for the test suite (versions pinned in package-lock.json).
if [ "$mode" = test ]; then
  echo "== npm packages"
  npm ci --no-audit --no-fund --loglevel=error
fi

# Step: build: the demo needs the program and the Draco library Blender's glTF importer loads
# (build/blender/libextern_draco.so, which scripts/blender_import.py finds: Debian's Blender ships none);
# test and build make everything (tests, benchmarks).
echo "== building in $build_dir"
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
if [ "$mode" = demo ]; then
  cmake --build "$build_dir" -j "$jobs" --target apparent blender_draco
else
  cmake --build "$build_dir" -j "$jobs"
fi

case "$mode" in
  demo)
    echo "== rendering data/scenes/flanges.json into out/"
    "$build_dir/apparent" render data/scenes/flanges.json --out out --model all --format glb,ply
    ;;
  test)
    echo "== running the test suite"
    cd "$build_dir"
    ctest --output-on-failure -j "$jobs"
    ;;
esac
