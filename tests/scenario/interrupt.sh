# Sourced by the resume and sweep-stop tests.
# interrupt_when PID FILE: sends SIGINT to PID once FILE exists (a checkpoint), waits for it and checks that it
# exited with 130, as a run or sweep stopped by a signal does.
interrupt_when() {
  local pid=$1 file=$2 rc=0
  for _ in $(seq 1 1200); do
    [ -f "$file" ] && break
    sleep 0.02
  done
  kill -INT "$pid" 2> /dev/null || { echo "FAIL: $pid ended before SIGINT"; exit 1; }
  wait "$pid" || rc=$?
  [ "$rc" = 130 ] || { echo "FAIL: $pid exited $rc after SIGINT, expected 130"; exit 1; }
}
# interrupt_and_resume DIPPER SCENARIO DIR FILE: runs SCENARIO into DIR, stops it with SIGINT once FILE exists in
# DIR, and resumes it to the end.
interrupt_and_resume() {
  local dipper=$1 scenario=$2 dir=$3 file=$4
  "$dipper" run "$scenario" --out "$dir" --quiet > /dev/null 2>&1 &
  interrupt_when $! "$dir/$file"
  "$dipper" resume "$dir" --quiet > "$dir.log" 2>&1 || { echo "FAIL: resume after SIGINT"; cat "$dir.log"; exit 1; }
}
