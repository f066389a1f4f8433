#!/usr/bin/env bash
# Sets everything up, builds, and runs every test. Tests that use UDP multicast run in
# private network namespaces (tests/netns_run.sh), so nothing leaves this machine.
# Then the decoders' and readers' unit tests again under AddressSanitizer and UBSan, and
# each fuzz harness for a bounded time (both in build-sanitize; docs/design.md, "Fuzzing").
# Every part runs even when an earlier one failed; the exit code says whether all passed.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh build
failed=()
ctest --test-dir build --output-on-failure -j"$(nproc)" || failed+=(tests)
tests/sanitized_tests.sh build-sanitize || failed+=(sanitized-tests)
tests/fuzz/run_fuzzers.sh --build build-sanitize --seconds 15 || failed+=(fuzzers)
if ((${#failed[@]})); then
  echo "test.sh: FAILED: ${failed[*]}" >&2
  exit 1
fi
