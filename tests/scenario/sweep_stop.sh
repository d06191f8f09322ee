#!/usr/bin/env bash
# Sends SIGINT to a sweep of two variants on one process while its first variant runs (once it has written a
# checkpoint): the sweep exits with 130, the first variant is interrupted with its checkpoint kept, the second is
# never started, and no table is written.
# usage: sweep_stop.sh DIPPER SWEEP WORKDIR
set -euo pipefail
dipper=$1 sweep=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
. "$(dirname "$0")/interrupt.sh"

"$dipper" sweep "$sweep" --out "$work/out" --quiet > "$work/log" 2>&1 &
interrupt_when $! "$work/out/variant_000/checkpoint.bin"
status=$(sed -n 's/.*"status": "\([a-z]*\)".*/\1/p' "$work/out/variant_000/summary.json")
[ "$status" = interrupted ] || { echo "FAIL: the first variant's status is '$status', expected interrupted"; exit 1; }
[ -f "$work/out/variant_000/checkpoint.bin" ] || { echo "FAIL: the interrupted variant lost its checkpoint"; exit 1; }
[ ! -e "$work/out/variant_001" ] || { echo "FAIL: the second variant was started after the signal"; exit 1; }
[ ! -e "$work/out/sweep.csv" ] || { echo "FAIL: a table was written for a stopped sweep"; exit 1; }
grep -q "stopped by a signal" "$work/log" || { echo "FAIL: the sweep did not say it was stopped"; cat "$work/log"; exit 1; }
echo "a sweep stopped by SIGINT in its first variant: exit 130, variant 0 interrupted with its checkpoint, variant 1 not started"
