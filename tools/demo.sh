#!/usr/bin/env bash
# The quick-start demo: covtrackd with the simulated trackers of config/sim.toml, and
# `covtrack echo` showing their streams live. Ctrl-C ends both.
#
# Both run inside a private network namespace whose only interface is loopback, so the
# demo works on any machine (no multicast route needed) and sends nothing outside it.
# To serve your network instead: build/server/covtrackd --config config/sim.toml
set -euo pipefail
cd "$(dirname "$0")/.."
config=${1:-config/sim.toml}

if [ "${COVTRACK_DEMO_IN_NETNS:-0}" != 1 ]; then
  tools/setup.sh build
  COVTRACK_DEMO_IN_NETNS=1 exec tests/netns_run.sh "$0" "$config"
fi

build/server/covtrackd --config "$config" --log-level warn &
daemon=$!
trap 'kill -TERM $daemon 2>/dev/null; wait $daemon 2>/dev/null' EXIT
build/tools/covtrack/covtrack echo
