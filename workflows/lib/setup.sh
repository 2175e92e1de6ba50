# Shared set-up for ./workflows/quickstart.sh and ./tests/run.sh (sourced).
#
#   pdcg_install_dependencies   install the missing Debian packages (root), or
#                               print the exact apt-get line and stop (not root)
#   pdcg_build                  configure (first time) and build into build/
#
# Both are idempotent and fast when nothing changed.

PDCG_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
PDCG_BUILD=${PDCG_BUILD:-$PDCG_ROOT/build}

# Debian 12 packages pdcg needs to build, test and run its workflows.
PDCG_PACKAGES=(
  build-essential cmake ninja-build pkg-config git ca-certificates
  libeigen3-dev libfftw3-dev libhdf5-dev libsuitesparse-dev libyaml-cpp-dev
  libcli11-dev libspdlog-dev libfmt-dev zlib1g-dev libnanoflann-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libopenblas0-openmp  # BLAS of the sparse direct solvers (reference BLAS: ~5× slower)
  liblammps-dev lammps lammps-data python3-lammps
  python3 python3-numpy python3-h5py python3-matplotlib
  python3-dev pybind11-dev python3-pytest python3-ase python3-yaml  # the Python module (docs/python.md)
  petsc-dev libopenmpi-dev openmpi-bin  # distributed runs, mpirun -n N pdcg run (docs/scale-out.md)
)
# Extra packages of the sanitizer and fuzzing checks (tests/sanitize.sh, tests/fuzz/run.sh):
# clang, libFuzzer, the sanitizer runtimes, clang's OpenMP, llvm-symbolizer (file:line in the
# reports). Installed when PDCG_CHECKS=1 (tests/run.sh's default, and those scripts set it).
PDCG_CHECK_PACKAGES=(clang-14 libfuzzer-14-dev libclang-rt-14-dev libomp-14-dev llvm-14)
# Extra packages of the test suite only (tests/run.sh sets PDCG_TESTS=1): ParaView's batch
# Python and a virtual X server for the test that opens a run's results.xdmf in ParaView
# (tests/paraview/); ~70 MB to download, about 2 minutes to install.
PDCG_TEST_PACKAGES=(paraview python3-paraview xvfb)

pdcg_missing_packages() {
  local missing=() p status wanted=("${PDCG_PACKAGES[@]}")
  [ "${PDCG_CHECKS:-0}" = 1 ] && wanted+=("${PDCG_CHECK_PACKAGES[@]}")
  [ "${PDCG_TESTS:-0}" = 1 ] && wanted+=("${PDCG_TEST_PACKAGES[@]}")
  for p in "${wanted[@]}"; do
    status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
    [[ "$status" == "install ok installed" ]] || missing+=("$p")
  done
  echo "${missing[@]}"
}

pdcg_install_dependencies() {
  if ! command -v dpkg-query >/dev/null; then
    echo "pdcg: this script installs Debian packages; on another system install: ${PDCG_PACKAGES[*]}" >&2
    return 1
  fi
  local missing
  missing=$(pdcg_missing_packages)
  [ -z "$missing" ] && return 0
  if [ "$(id -u)" != 0 ]; then
    echo "pdcg: missing Debian packages. Run as root:" >&2
    echo "  apt-get update && apt-get install -y --no-install-recommends $missing" >&2
    return 1
  fi
  echo "pdcg: installing missing Debian packages: $missing" >&2
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  # shellcheck disable=SC2086
  apt-get install -y -qq --no-install-recommends $missing >/dev/null
}

pdcg_build() {
  local gen=()
  command -v ninja >/dev/null && gen=(-G Ninja)
  if [ ! -f "$PDCG_BUILD/CMakeCache.txt" ]; then
    cmake -S "$PDCG_ROOT" -B "$PDCG_BUILD" "${gen[@]}" -DCMAKE_BUILD_TYPE=Release "$@"
  fi
  cmake --build "$PDCG_BUILD" -j"${PDCG_JOBS:-2}"
}

# pdcg_seed_test_costs <build-dir>: a build tree that has never run ctest gets the test costs
# of a measured run (tests/ctest-costs.txt, ctest's own CTestCostData format: name, runs,
# seconds), so that `ctest -j2` starts the long tests first instead of leaving them for a
# one-core tail. ctest replaces the file with its own measurements after each run; a test
# missing from the seed only runs in its default place, so a stale seed costs time, never a
# result.
pdcg_seed_test_costs() {
  local cost=$1/Testing/Temporary/CTestCostData.txt
  [ -f "$cost" ] && return 0
  mkdir -p "$(dirname "$cost")"
  cp "$PDCG_ROOT/tests/ctest-costs.txt" "$cost"
}
