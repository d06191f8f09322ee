#!/usr/bin/env bash
# A run with rocks, the shovel and wear stopped with --stop-after and with SIGINT resumes to within the
# limits that Bullet's unsaved contact caches allow (tests/CMakeLists.txt states them), and a resume of the
# ended run adds no row to probes.csv. SIGKILL is kill_resume.sh's.
# usage: resume_coupled_stops.sh DIPPER SCENARIO WORKDIR COMPARE...
set -euo pipefail
source "$(dirname "$0")/interrupt.sh"
dipper=$1 scenario=$2 work=$3
shift 3
rm -rf "$work" && mkdir -p "$work"
"$dipper" run "$scenario" --out "$work/whole" --quiet > /dev/null

rc=0
"$dipper" run "$scenario" --out "$work/stopped" --stop-after 0.15 --quiet > /dev/null || rc=$?
[ "$rc" = 130 ] || { echo "FAIL: run --stop-after 0.15 exited $rc, expected 130"; exit 1; }
"$dipper" resume "$work/stopped" --quiet > "$work/stopped.log" 2>&1 || { echo "FAIL: resume after --stop-after"; cat "$work/stopped.log"; exit 1; }
"$@" "$work/whole" "$work/stopped"

# after the second checkpoint (0.2 s), as kill_resume.sh: a stop while the rocks are still landing on the
# dipper (0.05-0.1 s) lets single spheres part by 120-240 mm by 0.3 s (median 0), beyond the limits
interrupt_and_resume "$dipper" "$scenario" "$work/interrupted" checkpoint.prev.bin
"$@" "$work/whole" "$work/interrupted"

rows=$(wc -l < "$work/whole/probes.csv")
"$dipper" resume "$work/whole" --quiet > /dev/null 2>&1 || { echo "FAIL: resume of the ended run"; exit 1; }
[ "$(wc -l < "$work/whole/probes.csv")" = "$rows" ] || { echo "FAIL: resume of the ended run added rows"; exit 1; }
echo "rocks, shovel and wear: stopped at 0.15 s and by SIGINT, resumed within the limits; an ended run resumed adds no row"
