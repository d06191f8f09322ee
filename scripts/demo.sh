#!/usr/bin/env bash
# The main job: installs what is missing, builds, and runs the quick loading scenario (one pass of the rope
# shovel through a pile of Aitik ore, with the dipper's wear), then prints the pass and where the report is.
# Extra arguments go to `dipper run` (for example --threads 1).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh build
out=out/loading_quick
./build/dipper run examples/scenarios/loading_quick.yaml --out "$out" "$@"
echo
sed -n '/^| pass |/,/^$/p' "$out/report.md"
echo "report: $out/report.md (figures: dig force, material in the dipper, mass per pass, the dipper's wear in 3-D)"
echo "ParaView: $out/particles.pvd, $out/wall_dipper.pvd, $out/wear_dipper.pvd"
