#!/usr/bin/env bash
# Runs a small sweep serially and under mpirun with 2 ranks; the two tables must be equal byte for byte.
# usage: sweep_mpi.sh DIPPER SWEEP WORKDIR
set -euo pipefail
dipper=$1 sweep=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
"$dipper" sweep "$sweep" --out "$work/serial" --quiet > /dev/null
# OpenMPI keeps memory of its own until exit; in a sanitizer build the leak check would report it as ours
ASAN_OPTIONS="${ASAN_OPTIONS:-}:detect_leaks=0" \
  mpirun --allow-run-as-root --oversubscribe -np 2 "$dipper" sweep "$sweep" --out "$work/mpi" --quiet > "$work/mpi.log"
grep -q "on 2 processes" "$work/mpi.log" || { echo "FAIL: the sweep did not run on 2 ranks"; cat "$work/mpi.log"; exit 1; }
rows=$(($(wc -l < "$work/serial/sweep.csv") - 1))
[ "$rows" -eq 4 ] || { echo "FAIL: $rows variants in the table, expected 4"; exit 1; }
cmp "$work/serial/sweep.csv" "$work/mpi/sweep.csv" || { echo "FAIL: tables differ"; exit 1; }
echo "sweep of $rows variants: the 2-rank table equals the serial one"
