# Sourced by the resume tests. interrupt_and_resume DIPPER SCENARIO DIR FILE: runs SCENARIO into DIR, sends
# SIGINT once FILE exists in DIR (a checkpoint), checks the run stopped with 130, and resumes it to the end.
interrupt_and_resume() {
  local dipper=$1 scenario=$2 dir=$3 file=$4 pid rc=0
  "$dipper" run "$scenario" --out "$dir" --quiet > /dev/null 2>&1 &
  pid=$!
  for _ in $(seq 1 1200); do
    [ -f "$dir/$file" ] && break
    sleep 0.02
  done
  kill -INT "$pid" 2> /dev/null || { echo "FAIL: the run ended before SIGINT"; exit 1; }
  wait "$pid" || rc=$?
  [ "$rc" = 130 ] || { echo "FAIL: the run exited $rc after SIGINT, expected 130"; exit 1; }
  "$dipper" resume "$dir" --quiet > "$dir.log" 2>&1 || { echo "FAIL: resume after SIGINT"; cat "$dir.log"; exit 1; }
}
