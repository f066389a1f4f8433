#!/usr/bin/env bash
# Sets everything up, builds, and runs every test. Tests that use UDP multicast run in
# private network namespaces (tests/netns_run.sh), so nothing leaves this machine.
# Then the decoders' and readers' unit tests again under AddressSanitizer and UBSan, and
# each fuzz harness for a bounded time (both in build-sanitize, which builds while the
# plain tests run; docs/design.md, "Fuzzing").
# Every part runs even when an earlier one failed; the exit code says whether all passed.
set -euo pipefail
cd "$(dirname "$0")/.."
# mark PHASE: how long the run has taken so far, so a slow CI run shows where its time went.
mark() { echo "test.sh: $1 after ${SECONDS} s"; }
tools/setup.sh build
mark "set-up and build"
failed=()
# The instrumented tree builds while the plain suite runs, in the idle scheduling class:
# the suite spends much of its time waiting on daemons, namespaces and timers, and an
# idle-class process gets only the CPU time that nothing else wants, so the tests still
# run on an otherwise quiet machine.
mkdir -p build-sanitize
chrt --idle 0 tests/sanitized_tests.sh --build-only build-sanitize >build-sanitize/build.log 2>&1 &
sanitized_build=$!
ctest --test-dir build --output-on-failure -j"$(nproc)" || failed+=(tests)
mark "tests"
if ! wait "$sanitized_build"; then
  tail -n 40 build-sanitize/build.log
  failed+=(sanitized-build)
fi
mark "instrumented build"
tests/sanitized_tests.sh build-sanitize || failed+=(sanitized-tests)
mark "sanitized tests"
tests/fuzz/run_fuzzers.sh --build build-sanitize --seconds 5 || failed+=(fuzzers)
mark "fuzzers"
if ((${#failed[@]})); then
  echo "test.sh: FAILED: ${failed[*]}" >&2
  exit 1
fi
