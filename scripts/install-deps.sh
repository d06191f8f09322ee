#!/usr/bin/env bash
# Installs the Debian packages dipper needs to build, test and report; skips what is present.
# Usage: scripts/install-deps.sh        (needs root or sudo for apt-get)
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libassimp-dev        # mesh files (STL, OBJ, PLY)
  zlib1g-dev           # the VTK output's arrays compressed
  libbullet-dev        # rigid rocks and the shovel (double-precision libraries)
  libeigen3-dev        # small dense linear algebra (principal axes of inertia)
  libccd-dev           # independent sphere-convex penetration, checked against our own in the tests
  libfcl-dev           # the machine's path checked against the walls (FCL)
  libyaml-cpp-dev      # scenario files
  libopenmpi-dev openmpi-bin  # sweeps spread over MPI ranks
  python3-matplotlib python3-pil  # run reports (figures; the film as an animated GIF)
  catch2               # unit and analytic tests (v2.13)
  libbenchmark-dev     # micro-benchmarks
  libomp-dev           # OpenMP runtime headers for clang users; g++ ships libgomp
  python3 python3-vtk9 # tests read our VTK output with the real VTK reader; the report draws with VTK
  xvfb libgl1-mesa-dri # an X server in memory and Mesa's software OpenGL for VTK's renderer without a display
  python3-dev pybind11-dev python3-numpy  # the Python module dipper
  python3-pytest python3-yaml python3-pandas  # its tests; scenarios from dicts; tables as DataFrames
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
