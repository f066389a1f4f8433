#!/usr/bin/env bash
# Runs a command on a virtual X server of its own (Xvfb, 24-bit, 1280x1024), for the
# tests that draw with OpenGL or open windows. Xvfb picks a free display itself
# (-displayfd): tests run in parallel cannot end up on one display, as with
# `xvfb-run -a`, where two can both take :99 and the first to finish takes the other's
# server away mid-test.
# Usage: tests/with_xvfb.sh COMMAND [ARGS...]
set -euo pipefail
dir=$(mktemp -d)
mkfifo "$dir/display"
# -noreset: an X server resets when its last client leaves, and a connection asked for
# meanwhile fails ("unable to open display"): tests open one after another.
Xvfb -displayfd 3 -screen 0 1280x1024x24 -nolisten tcp -noreset 3>"$dir/display" 2>"$dir/log" &
xvfb=$!
trap 'kill "$xvfb" 2>/dev/null; wait "$xvfb" 2>/dev/null; rm -rf "$dir"' EXIT
# Xvfb writes its display number once it accepts connections.
if ! read -r -t 30 display < "$dir/display" || [ -z "$display" ]; then
  echo "with_xvfb.sh: Xvfb gave no display within 30 s:" >&2
  cat "$dir/log" >&2
  exit 1
fi
DISPLAY=":$display" "$@"
