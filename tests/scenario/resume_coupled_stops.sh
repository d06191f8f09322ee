#!/usr/bin/env bash
# A run with rocks, the shovel and wear stopped with --stop-after (while its rocks land on the dipper, and
# later) and with SIGINT resumes to the uninterrupted run's state hash and probes.csv, and a resume of the
# ended run adds no row to probes.csv. SIGKILL is kill_resume.sh's.
# usage: resume_coupled_stops.sh DIPPER SCENARIO WORKDIR
set -euo pipefail
source "$(dirname "$0")/interrupt.sh"
dipper=$1 scenario=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
hash() { sed -n 's/.*"state_hash": "\([0-9a-f]*\)".*/\1/p' "$1/summary.json"; }
same_as_whole() {  # same_as_whole DIR WHAT
  [ "$(hash "$work/whole")" = "$(hash "$1")" ] || { echo "FAIL: $2: state hash $(hash "$1"), uninterrupted $(hash "$work/whole")"; exit 1; }
  cmp <(sed 's/,[^,]*,[^,]*$//' "$work/whole/probes.csv") <(sed 's/,[^,]*,[^,]*$//' "$1/probes.csv") ||
    { echo "FAIL: $2: probes.csv differs from the uninterrupted run's"; exit 1; }
}
"$dipper" run "$scenario" --out "$work/whole" --quiet > /dev/null

for stop in 0.07 0.15; do
  rc=0
  "$dipper" run "$scenario" --out "$work/stopped_$stop" --stop-after $stop --quiet > /dev/null || rc=$?
  [ "$rc" = 130 ] || { echo "FAIL: run --stop-after $stop exited $rc, expected 130"; exit 1; }
  "$dipper" resume "$work/stopped_$stop" --quiet > "$work/stopped.log" 2>&1 || { echo "FAIL: resume after --stop-after $stop"; cat "$work/stopped.log"; exit 1; }
  same_as_whole "$work/stopped_$stop" "stopped at $stop s and resumed"
done

interrupt_and_resume "$dipper" "$scenario" "$work/interrupted" checkpoint.prev.bin
same_as_whole "$work/interrupted" "stopped by SIGINT and resumed"

rows=$(wc -l < "$work/whole/probes.csv")
"$dipper" resume "$work/whole" --quiet > /dev/null 2>&1 || { echo "FAIL: resume of the ended run"; exit 1; }
[ "$(wc -l < "$work/whole/probes.csv")" = "$rows" ] || { echo "FAIL: resume of the ended run added rows"; exit 1; }
echo "rocks, shovel and wear: stopped at 0.07 and 0.15 s and by SIGINT, each resume ends with state hash $(hash "$work/whole"); an ended run resumed adds no row"
