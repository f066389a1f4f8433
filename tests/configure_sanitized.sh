#!/usr/bin/env bash
# Configures the instrumented build tree that the fuzzers and the sanitized tests share:
# clang 16, -O1 with line tables, every library built with AddressSanitizer, UBSan and
# libFuzzer's coverage (-DCOVTRACK_FUZZ=ON, cmake/CovtrackFuzz.cmake); a unity build built
# by Ninja when new, as tools/setup.sh's; ccache when found.
# Usage: tests/configure_sanitized.sh BUILD_DIR
set -euo pipefail
cd "$(dirname "$0")/.."
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
generator=()
[[ -f "$1/CMakeCache.txt" ]] || generator=(-G Ninja)
cmake "${generator[@]}" -S . -B "$1" -DCOVTRACK_FUZZ=ON -DCMAKE_BUILD_TYPE=Release \
      -DCMAKE_CXX_COMPILER=clang++-16 -DCMAKE_C_COMPILER=clang-16 -DCMAKE_UNITY_BUILD=ON "${launcher[@]}" \
      "-DCMAKE_CXX_FLAGS_RELEASE=-O1 -gline-tables-only" "-DCMAKE_C_FLAGS_RELEASE=-O1 -gline-tables-only" \
      -DCOVTRACK_BUILD_BENCHMARKS=OFF >/dev/null
