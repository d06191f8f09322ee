#!/usr/bin/env bash
# Runs the input fuzzer for a bounded time on a copy of the corpus, with a checkpoint made for it first
# (runs of the corpus' pour and rocks stopped at 5 ms) and a saved pile (the corpus' rocks), and prints its counts.
# usage: run_fuzz.sh DIPPER FUZZER CORPUS_DIR WORKDIR SECONDS [SEED]
set -euo pipefail
dipper=$1 fuzzer=$2 corpus=$3 work=$4 seconds=$5 seed=${6:-1}
rm -rf "$work" && mkdir -p "$work"
cp -r "$corpus" "$work/corpus"
rc=0
"$dipper" run "$work/corpus/pour.yaml" --out "$work/corpus/checkpoint" --stop-after 0.005 --quiet > /dev/null 2>&1 || rc=$?
[ "$rc" = 130 ] || { echo "FAIL: the corpus checkpoint run exited $rc, expected 130"; exit 1; }
find "$work/corpus/checkpoint" -type f ! -name checkpoint.bin ! -name probes.csv -delete
# and one with rocks (Bullet's broad phase, pairs and manifolds in it), stopped at the same time
rc=0
"$dipper" run "$work/corpus/rocks.yaml" --out "$work/corpus/rock_checkpoint" --stop-after 0.005 --quiet > /dev/null 2>&1 || rc=$?
[ "$rc" = 130 ] || { echo "FAIL: the corpus rock checkpoint run exited $rc, expected 130"; exit 1; }
find "$work/corpus/rock_checkpoint" -type f ! -name checkpoint.bin ! -name probes.csv -delete
"$dipper" run "$work/corpus/rocks.yaml" --out "$work/corpus/pile" --quiet > /dev/null 2>&1 || { echo "FAIL: the corpus pile run"; exit 1; }
find "$work/corpus/pile" -type f ! -name pile.txt -delete
"$fuzzer" "$work/corpus" "$work/out" --seconds "$seconds" --seed "$seed"
