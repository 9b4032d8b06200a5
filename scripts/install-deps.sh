#!/usr/bin/env bash
# Installs shelldyn's build and test dependencies from Debian 12's packages (run as root).
# Idempotent: does nothing (not even `apt-get update`) when every package is already installed.
#   bash scripts/install-deps.sh              # what the default build and tests need
#   bash scripts/install-deps.sh --with-mpi   # also Open MPI: MPI-distributed sweeps (docs/cluster-sweeps.md)
#   bash scripts/install-deps.sh --with-docs  # also MkDocs, Doxygen, Chromium: the documentation site (scripts/docs.sh)
set -euo pipefail

PACKAGES=(
  cmake g++ make                       # toolchain
  libsundials-dev                      # SUNDIALS 6.4.1: KINSOL, IDA, ARKODE (+ KLU linear solver)
  libsuitesparse-dev                   # KLU, CHOLMOD
  libmumps-seq-dev                     # sequential MUMPS: the "mumps" linear solver (lib/linalg/linear_solver.cpp)
  libopenblas0-pthread                 # fast BLAS for CHOLMOD's supernodal factorization
  libeigen3-dev                        # Eigen 3.4
  libyaml-cpp-dev libcli11-dev         # case files, command line
  nlohmann-json3-dev                   # run.json and checkpoints (lib/io/run_info, integrators/checkpoint)
  libspectra-dev                       # Spectra: shift-invert Lanczos of `shelldyn modes` (header-only)
  libgtest-dev libgmock-dev            # unit tests
  libbenchmark-dev                     # performance programs
  python3 python3-meshio               # VTU round-trip check in the test suite
  python3-matplotlib                   # plots of the apps and `shelldyn compare` (scripts/plot_*.py)
  pybind11-dev python3-dev             # the shelldyn Python module (python/, SHELLDYN_WITH_PYTHON)
  python3-numpy python3-scipy python3-pytest   # its arrays, sparse matrices and tests
)
# Not listed (opt-in tools): clang-14 libclang-rt-14-dev for scripts/fuzz.sh (libFuzzer); .ci/run
# installs them itself when SHELLDYN_CI_SANITIZE=1.

for flag in "$@"; do
  case "$flag" in
    --with-mpi) PACKAGES+=(libopenmpi-dev openmpi-bin) ;;   # optional: SHELLDYN_WITH_MPI, `mpirun -n P shelldyn compare`
    --with-docs) PACKAGES+=(mkdocs doxygen chromium) ;;     # optional: the documentation site (scripts/docs.sh) and its browser test
    *) echo "install-deps: unknown option '$flag' (use --with-mpi, --with-docs)" >&2; exit 2 ;;
  esac
done

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then
    SUDO="sudo"
  else
    echo "install-deps: missing packages: ${missing[*]}" >&2
    echo "install-deps: run this script as root to install them" >&2
    exit 1
  fi
fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO env DEBIAN_FRONTEND=noninteractive apt-get update -qq
$SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"
