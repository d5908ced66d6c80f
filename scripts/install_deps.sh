#!/usr/bin/env bash
# Installs streamrt's build and test dependencies from Debian 12's packages (run as root).
# Does nothing when everything is already there.
set -euo pipefail
packages=(g++ cmake ninja-build pkg-config libxsimd-dev xtl-dev libtbb-dev libglm-dev libstb-dev
          doctest-dev libcli11-dev libbenchmark-dev libtinyobjloader-dev python3-matplotlib
          zlib1g-dev libdeflate-dev libopenexr-dev python3-numpy clang-14 libclang-rt-14-dev
          pybind11-dev python3-dev python3-pytest  # the Python module (docs/python.md) and its tests
          python3-venv python3-setuptools python3-wheel  # pip install --no-build-isolation . in a venv (ctest python_package)
          libopenmpi-dev openmpi-bin  # MPI (streamrt --mpi): optional for the build, tested when found
          povray  # POV-Ray 3.7: CSG's independent check (ctest csg_against_povray) and the peer benchmark
          libcpp-httplib-dev  # the HTTP server of streamrt serve (docs/preview.md): optional for the build, tested when found
          embree-tools  # Embree's tutorial path tracer and its Cornell box: degree 6's independent check (scripts/gi_peer.py)
          dpkg-dev)  # dpkg-dev: dpkg-source, for the oneTBB source package (sanitize.sh tsan)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "installing: ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
