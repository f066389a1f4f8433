#!/usr/bin/env bash
# Builds the unit tests of the pure parts (protocol and wire decoding, the device
# decoders, the config, layout, scene and camera calibration readers, LCM log reading and
# replay, the client's sequence tracking) with AddressSanitizer and UndefinedBehaviorSanitizer,
# and runs them with the fuzz corpora (replayed once). Any sanitizer report fails the test
# that made it.
# The renders, the OpenGL, the end-to-end daemon and the client's Monte Carlo tests
# (graph_test: minutes under the sanitizers) are left to the plain build (tools/test.sh).
# Usage: tests/sanitized_tests.sh [--build-only] [BUILD_DIR]   (default: build-sanitize)
set -euo pipefail
cd "$(dirname "$0")/.."
build_only=false
if [[ ${1:-} == --build-only ]]; then build_only=true; shift; fi
build=${1:-build-sanitize}
tests=(protocol_test channels_test wire_decode_test lcm_datagram_test message_auth_test lenz_decoder_test
       serial6dof_decoder_test hydra_test motion_gate_test vrpn_wire_test config_test vrpn_config_test
       lcmlog_file_test lcmlog_replay_test scene_test sequence_tracker_test camera_file_test)
tests/configure_sanitized.sh "$build"
cmake --build "$build" -j"$(nproc)" --target "${tests[@]}" covtrack_fuzzers
$build_only && exit 0
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
regex="^($(IFS='|'; echo "${tests[*]}")|fuzz_.*)\$"
ctest --test-dir "$build" -R "$regex" --output-on-failure -j"$(nproc)"
