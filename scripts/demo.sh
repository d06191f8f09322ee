#!/usr/bin/env bash
# The main job: installs what is missing, builds, and runs the default scenario (for now: Aitik ore
# poured into a box and settled), printing its results and writing ParaView files to out/demo_settle.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh build
./build/examples/dipper_demo_settle --out out/demo_settle "$@"
