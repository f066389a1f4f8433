#!/usr/bin/env bash
# Sets everything up, builds, and runs every test. Tests that use UDP multicast run in
# private network namespaces (tests/netns_run.sh), so nothing leaves this machine.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh build
ctest --test-dir build --output-on-failure -j"$(nproc)"
