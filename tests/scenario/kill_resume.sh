#!/usr/bin/env bash
# Kills a dipper run with SIGKILL after it has written its second checkpoint, resumes it, and compares its
# end with an uninterrupted run of the same scenario: bit for bit (state hash and probes.csv).
# usage: kill_resume.sh DIPPER SCENARIO WORKDIR
set -euo pipefail
dipper=$1 scenario=$2 work=$3
rm -rf "$work" && mkdir -p "$work"

"$dipper" run "$scenario" --out "$work/whole" --quiet > /dev/null

"$dipper" run "$scenario" --out "$work/killed" --quiet > /dev/null 2>&1 &
pid=$!
# wait for the second checkpoint (t = 0.1 s), then kill without warning
for _ in $(seq 1 1200); do
  [ -f "$work/killed/checkpoint.prev.bin" ] && break
  sleep 0.05
done
kill -9 "$pid" 2> /dev/null || { echo "FAIL: the run ended before it could be killed"; exit 1; }
wait "$pid" 2> /dev/null || true
[ ! -f "$work/killed/summary.json" ] || { echo "FAIL: the killed run wrote a summary, so it was not killed mid-run"; exit 1; }

"$dipper" resume "$work/killed" --quiet > "$work/resume.log"
hash() { sed -n 's/.*"state_hash": "\([0-9a-f]*\)".*/\1/p' "$1/summary.json"; }
status=$(sed -n 's/.*"status": "\([a-z]*\)".*/\1/p' "$work/killed/summary.json")
[ "$status" = completed ] || { echo "FAIL: resumed run status '$status'"; exit 1; }
[ "$(hash "$work/whole")" = "$(hash "$work/killed")" ] ||
  { echo "FAIL: state hash $(hash "$work/killed") after resume, $(hash "$work/whole") uninterrupted"; exit 1; }
cmp <(sed 's/,[^,]*,[^,]*$//' "$work/whole/probes.csv") <(sed 's/,[^,]*,[^,]*$//' "$work/killed/probes.csv") ||
  { echo "FAIL: probes.csv differs"; exit 1; }
echo "killed after a checkpoint, resumed: state hash $(hash "$work/whole") and probes.csv equal to the uninterrupted run"
