#!/usr/bin/env bash
# The quick-start demo: covtrackd with the simulated trackers of config/sim.toml, and
# `covtrack echo` showing their streams live; with a display, `covtrack view` also draws
# the registration error of config/scenes/sim_lab.toml live. Ctrl-C ends them all.
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
pids=$!
trap 'kill -TERM $pids 2>/dev/null; wait $pids 2>/dev/null' EXIT
if [ -n "${DISPLAY:-}" ] && [ "$config" = config/sim.toml ]; then
  build/tools/covtrack/covtrack view config/scenes/sim_lab.toml --live &
  pids="$pids $!"
fi
build/tools/covtrack/covtrack echo
