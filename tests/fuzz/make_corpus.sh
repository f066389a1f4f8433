#!/usr/bin/env bash
# Rewrites the seed corpus of every harness (tests/fuzz/corpus/<harness>/seed_*): inputs
# made by the encoders (fuzz_make_corpus) and the shipped configs, layouts and scenes.
# Files not named seed_* (inputs that once found a bug, kept as regressions) stay.
# Usage: tests/fuzz/make_corpus.sh [BUILD_DIR]   (default: build; needs fuzz_make_corpus)
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:-build}
corpus=tests/fuzz/corpus
cmake --build "$build" --target fuzz_make_corpus >/dev/null
find "$corpus" -name 'seed_*' -delete 2>/dev/null || true
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
"$build/tests/fuzz/fuzz_make_corpus" "$scratch"
for dir in "$scratch"/*/; do
  harness=$(basename "$dir")
  mkdir -p "$corpus/$harness"
  for f in "$dir"*; do cp "$f" "$corpus/$harness/seed_$(basename "$f")"; done
done
copy() {  # copy HARNESS FILES...
  local harness=$1; shift
  mkdir -p "$corpus/$harness"
  for f in "$@"; do cp "$f" "$corpus/$harness/seed_$(basename "$f")"; done
}
copy daemon_config $(ls config/*.toml | grep -v layout)
copy lenz_layout config/lenz_layout.toml tests/data/lenz_short_layout.toml
copy scene config/scenes/*.toml
copy camera config/cameras/*.yml tests/data/ros_camera_info_640x480.yaml
# The start of a recorded Lenz session: raw device bytes and poses, cut mid-event.
head -c 4096 tests/data/lenz_session.lcm >"$corpus/lcm_log/seed_lenz_session_start"
du -sh "$corpus"
