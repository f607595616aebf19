#!/usr/bin/env bash
# Sets contactrom up on a Debian 12 machine: installs the Debian packages it
# needs (only those missing), configures and builds into ./build (Release,
# Ninja, tests on). Idempotent; safe to re-run.
#   tools/setup.sh            # install + configure + build everything (library, CLI, Python, tests)
#   tools/setup.sh contactrom # ... but build only the named targets (here the CLI and its libraries)
#   BUILD_DIR=b tools/setup.sh
#   CONTACTROM_SANITIZE=ON BUILD_DIR=build-asan tools/setup.sh   # ASan/UBSan build
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(build-essential cmake ninja-build pkg-config libeigen3-dev libsuitesparse-dev
          coinor-libipopt-dev gmsh libgmsh-dev libboost-test-dev libhdf5-dev libcli11-dev
          nlohmann-json3-dev libtomlplusplus-dev python3 python3-numpy python3-scipy python3-matplotlib python3-h5py
          pybind11-dev python3-pybind11 python3-pytest  # the Python module (build/python) and its tests
          doxygen libopenmpi-dev openmpi-bin  # doxygen: docs/Doxyfile (test docs.doxygen); MPI: CONTACTROM_MPI, mpirun ... offline (tests run mpirun as root)
          libopenblas0-pthread)  # OpenBLAS replaces the reference libblas.so.3/liblapack.so.3 under CHOLMOD, dpotri and Ipopt (docs/results.md, "BLAS")
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}" >&2
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "${missing[@]}" >/dev/null
fi

build="${BUILD_DIR:-build}"
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
      -DCONTACTROM_SANITIZE="${CONTACTROM_SANITIZE:-OFF}" >/dev/null
targets=()
for t in "$@"; do targets+=(--target "$t"); done
cmake --build "$build" -j"$(nproc)" "${targets[@]}"
