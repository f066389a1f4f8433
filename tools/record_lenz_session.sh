#!/usr/bin/env bash
# Records the short Lenz session in tests/data/lenz_session.lcm: `covtrack emulate-lenz`
# on the ten-section layout (config/lenz_layout.toml), covtrackd's lenz driver at
# 10 Hz, and `covtrack record` taking poses, truth (10 Hz), raw device bytes and status
# for 20 s. Everything runs inside a private network namespace.
# Usage: tools/record_lenz_session.sh [BUILD_DIR] [OUTPUT]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
out=${2:-tests/data/lenz_session.lcm}
if [ "${COVTRACK_IN_NETNS:-0}" != 1 ]; then
  exec tests/netns_run.sh "$0" "$build" "$out"
fi
tmp=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null; wait 2>/dev/null; rm -rf "$tmp"' EXIT
link="$tmp/li101f"
cat > "$tmp/lenz.toml" <<CONFIG
[devices.train]
type = "lenz"
parent_frame = "table"
port = "$link"
layout = "$PWD/config/lenz_layout.toml"
rate_hz = 10
CONFIG
"$build/tools/covtrack/covtrack" record "$out" --force --duration 20 &
recorder=$!
sleep 0.5
"$build/tools/covtrack/covtrack" emulate-lenz --layout config/lenz_layout.toml --link "$link" \
  --profile "0.4:5,0.15:3,0:2,0.35:4" --truth-hz 10 --device train --parent-frame table &
sleep 0.5
"$build/server/covtrackd" --config "$tmp/lenz.toml" --log-level warn &
wait $recorder
