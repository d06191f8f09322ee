#!/usr/bin/env bash
# A run with a pour stopped in every way a user stops one resumes to the uninterrupted run's state hash and
# probes.csv: --stop-after at a step where the pour has just added spheres (their neighbour lists are built
# at the next step, which the checkpoint was refused for), SIGINT, and resuming a run that has already ended
# (which appended its last row again).
# usage: resume_every_stop.sh DIPPER SCENARIO WORKDIR
set -euo pipefail
source "$(dirname "$0")/interrupt.sh"
dipper=$1 scenario=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
hash() { sed -n 's/.*"state_hash": "\([0-9a-f]*\)".*/\1/p' "$1/summary.json"; }
status() { sed -n 's/.*"status": "\([a-z]*\)".*/\1/p' "$1/summary.json"; }
same_as_whole() {  # same_as_whole DIR WHAT
  [ "$(status "$1")" = completed ] || { echo "FAIL: $2: status '$(status "$1")'"; exit 1; }
  [ "$(hash "$work/whole")" = "$(hash "$1")" ] || { echo "FAIL: $2: state hash $(hash "$1"), uninterrupted $(hash "$work/whole")"; exit 1; }
  cmp <(sed 's/,[^,]*,[^,]*$//' "$work/whole/probes.csv") <(sed 's/,[^,]*,[^,]*$//' "$1/probes.csv") ||
    { echo "FAIL: $2: probes.csv differs from the uninterrupted run's"; exit 1; }
}

"$dipper" run "$scenario" --out "$work/whole" --quiet > /dev/null
step_s=$(sed -n 's/.*"step_s": \([0-9.e+-]*\).*/\1/p' "$work/whole/summary.json")
# the pour looks every 20 steps while it runs (0 to 0.2 s) and adds a 0.05 m sphere (1.9 kg) each time the
# flow (2,000 kg/s) has delivered its mass, about every third look: stops at four looks in a row (steps
# 2,000, 2,020, 2,040, 2,060), so at least two of them come just after spheres were added
rc=0
"$dipper" run "$scenario" --out "$work/stopped" --stop-after "$(python3 -c "print(repr(2000 * $step_s))")" --quiet > /dev/null || rc=$?
[ "$rc" = 130 ] || { echo "FAIL: run --stop-after at step 2000 exited $rc, expected 130"; exit 1; }
for step in 2020 2040 2060; do
  rc=0
  "$dipper" resume "$work/stopped" --stop-after "$(python3 -c "print(repr($step * $step_s))")" --quiet > "$work/stopped.log" 2>&1 || rc=$?
  [ "$rc" = 130 ] || { echo "FAIL: resume --stop-after at step $step exited $rc, expected 130"; cat "$work/stopped.log"; exit 1; }
done
"$dipper" resume "$work/stopped" --quiet > "$work/stopped.log" 2>&1 || { echo "FAIL: the last resume"; cat "$work/stopped.log"; exit 1; }
same_as_whole "$work/stopped" "stopped at four steps while pouring and resumed"

interrupt_and_resume "$dipper" "$scenario" "$work/interrupted" checkpoint.bin
same_as_whole "$work/interrupted" "stopped by SIGINT and resumed"

rows=$(wc -l < "$work/whole/probes.csv")
"$dipper" resume "$work/whole" --quiet > "$work/again.log" 2>&1 || { echo "FAIL: resume of an ended run"; cat "$work/again.log"; exit 1; }
grep -q "the run had already ended" "$work/again.log" || { echo "FAIL: resume of an ended run did not say so"; cat "$work/again.log"; exit 1; }
[ "$(wc -l < "$work/whole/probes.csv")" = "$rows" ] || { echo "FAIL: resume of an ended run added rows to probes.csv"; exit 1; }
same_as_whole "$work/whole" "resumed after its end"
echo "stopped while pouring, by SIGINT, and after its end: each resume ends with state hash $(hash "$work/whole")"
