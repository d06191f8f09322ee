#!/usr/bin/env bash
# The dipper command line: an option its command does not take is refused (exit 2, naming the option and the
# options the command takes), not ignored; `resume --stop-after` stops a resumed run where asked (a time the run
# has passed is refused), and a run
# taken in three legs (run to 0.1 s, resume to 0.2 s, resume to the end) ends bit for bit as the whole run.
# usage: command_line.sh DIPPER SCENARIO WORKDIR
set -euo pipefail
dipper=$1 scenario=$2 work=$3
rm -rf "$work" && mkdir -p "$work"

refused() {  # refused MESSAGE ARGS...: the command must exit 2 and print MESSAGE
  local message=$1 rc=0
  shift
  "$dipper" "$@" > "$work/out.txt" 2>&1 || rc=$?
  [ "$rc" = 2 ] || { echo "FAIL: 'dipper $*' exited $rc, expected 2"; cat "$work/out.txt"; exit 1; }
  grep -qF -- "$message" "$work/out.txt" || { echo "FAIL: 'dipper $*' did not say: $message"; cat "$work/out.txt"; exit 1; }
}
refused "dipper: check does not take --threads; it takes no options" check "$scenario" --threads 2
refused "dipper: run does not take --from; it takes --out, --threads, --stop-after, --quiet" run "$scenario" --from x.bin
refused "dipper: sweep does not take --stop-after; it takes --out, --threads, --quiet" sweep x.yaml --stop-after 1
refused "dipper: report does not take --out; it takes no options" report "$work" --out x
refused "dipper: keys takes no arguments; got '--out'" keys --out x
refused "unknown command 'runn'" runn "$scenario" --out x

hash() { sed -n 's/.*"state_hash": "\([0-9a-f]*\)".*/\1/p' "$1/summary.json"; }
status() { sed -n 's/.*"status": "\([a-z]*\)".*/\1/p' "$1/summary.json"; }
time_s() { sed -n 's/.*"time_s": \([0-9.e+-]*\).*/\1/p' "$1/summary.json"; }
"$dipper" run "$scenario" --out "$work/whole" --quiet > /dev/null
rc=0
"$dipper" run "$scenario" --out "$work/legs" --stop-after 0.1 --quiet > /dev/null || rc=$?
[ "$rc" = 130 ] || { echo "FAIL: run --stop-after 0.1 exited $rc, expected 130"; exit 1; }
# a stop before the checkpoint's time is refused, and the checkpoint is left as it was
rc=0
"$dipper" resume "$work/legs" --stop-after 0.05 --quiet > "$work/early.log" 2>&1 || rc=$?
[ "$rc" = 1 ] || { echo "FAIL: resume --stop-after 0.05 from 0.1 s exited $rc, expected 1"; cat "$work/early.log"; exit 1; }
grep -q -- "--stop-after 0.05 s: the run is already at t = 0.1" "$work/early.log" ||
  { echo "FAIL: resume --stop-after 0.05 did not say why"; cat "$work/early.log"; exit 1; }
rc=0
"$dipper" resume "$work/legs" --stop-after 0.2 --quiet > "$work/leg2.log" || rc=$?
[ "$rc" = 130 ] || { echo "FAIL: resume --stop-after 0.2 exited $rc, expected 130"; cat "$work/leg2.log"; exit 1; }
[ "$(status "$work/legs")" = interrupted ] || { echo "FAIL: after resume --stop-after the status is '$(status "$work/legs")'"; exit 1; }
# the run stops at the first step that reaches 0.2 s: within one step (1.7e-5 s here, below the 1e-4 allowed)
python3 -c "import sys; t = float(sys.argv[1]); sys.exit(0 if 0.2 <= t < 0.2001 else 1)" "$(time_s "$work/legs")" ||
  { echo "FAIL: resume --stop-after 0.2 stopped at t = $(time_s "$work/legs") s"; exit 1; }
"$dipper" resume "$work/legs" --quiet > /dev/null
[ "$(status "$work/legs")" = completed ] || { echo "FAIL: the last leg's status is '$(status "$work/legs")'"; exit 1; }
[ "$(hash "$work/whole")" = "$(hash "$work/legs")" ] ||
  { echo "FAIL: state hash $(hash "$work/legs") after three legs, $(hash "$work/whole") whole"; exit 1; }
cmp <(sed 's/,[^,]*,[^,]*$//' "$work/whole/probes.csv") <(sed 's/,[^,]*,[^,]*$//' "$work/legs/probes.csv") ||
  { echo "FAIL: probes.csv of the legs differs from the whole run's"; exit 1; }
echo "options refused where their command does not take them; three legs (run, resume --stop-after, resume) end" \
     "with the whole run's state hash $(hash "$work/whole")"
