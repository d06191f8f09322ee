#!/usr/bin/env bash
# Installs what is missing, builds, and runs the test suite (everything but the [slow] scenario runs).
# With --sanitize: the same tests in a separate AddressSanitizer + UndefinedBehaviorSanitizer build.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "${1:-}" = "--sanitize" ]; then
  bash scripts/build.sh build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDIPPER_SANITIZE=ON \
    -DDIPPER_BUILD_BENCHMARKS=OFF -DDIPPER_BUILD_EXAMPLES=OFF -DDIPPER_BUILD_PYTHON=OFF
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  ctest --test-dir build-sanitize --output-on-failure --parallel "$(nproc)" -LE "slow|install"
else
  bash scripts/build.sh build -DDIPPER_WARNINGS_AS_ERRORS=ON
  ctest --test-dir build --output-on-failure --parallel "$(nproc)" -LE slow
fi
