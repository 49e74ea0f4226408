#!/usr/bin/env bash
# Installs the Debian 12 packages the project builds and tests with (idempotent).
set -euo pipefail
pkgs=(cmake g++ make pkg-config libeigen3-dev libbullet-dev libode-dev libmujoco-dev libqhull-dev
      libgtest-dev libgmock-dev libboost-dev libtomlplusplus-dev nlohmann-json3-dev libcli11-dev
      libbenchmark-dev gnuplot-nox
      python3-dev python3-pybind11 python3-numpy  # the Python module tippe (docs/library.md)
      python3-pandas python3-matplotlib  # tippe's to_pandas() and plot(), and their tests (docs/python.md)
      python3-setuptools python3-wheel python3-venv python3-pip  # pip install --no-build-isolation . (docs/python.md)
      python3-jsonschema  # the records against schemas/ (Library.RecordsMatchSchemas)
      libdart-dev libdart-external-ikfast-dev  # DART 6.12 (engines/dart/dart_sim.cpp); dart/dart.hpp needs ikfast's headers
      libdart-collision-bullet-dev  # DART's Bullet backend (engines.dart.collision_detector = "bullet"), in the DART module only
      libsimbody-dev  # Simbody 3.7 (engines/simbody/): the error-controlled, compliant-contact engine
      libsiconos-kernel-dev libsiconos-numerics-dev  # Siconos 4.4 (engines/siconos/): nonsmooth Moreau-Jean time-stepping; not its mechanics library (single-precision Bullet)
      chromium  # headless, for the check of every published page (tests/harness/report/test_published_pages.cpp)
      libopenmpi-dev openmpi-bin  # MPI sweeps: mpirun -np N tippe sweep (docs/cluster.md)
      clang libclang-rt-14-dev)  # clang 14 + its sanitizer and libFuzzer runtimes: scripts/sanitize.sh, scripts/fuzz.sh
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#pkgs[@]} packages present"
  exit 0
fi
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
