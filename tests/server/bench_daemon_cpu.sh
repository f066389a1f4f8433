#!/bin/sh
# Daemon CPU at 10 sensors x 1 kHz, against a plain LCM publisher of the same streams
# (bench_raw_publish) in the same run. Inside a private network namespace.
# Usage: tests/server/bench_daemon_cpu.sh BUILD_DIR [SECONDS]   (by hand; not in CTest)
set -e
if [ "$COVTRACK_BENCH_IN_NETNS" != 1 ]; then
  COVTRACK_BENCH_IN_NETNS=1 exec "$(dirname "$0")/../netns_run.sh" "$0" "$@"
fi
build=$(cd "${1:?usage: $0 BUILD_DIR [SECONDS]}" && pwd)
seconds=${2:-10}
config=$(mktemp /tmp/covtrack-bench-XXXXXX.toml)
trap 'rm -f "$config"' EXIT
cat > "$config" <<TOML
[devices.rig]
type = "sim"
sensor_count = 10
rate_hz = 1000
sigma_m = [0.001, 0.001, 0.001]
sigma_rad = [0.002, 0.002, 0.002]
TOML
url='udpm://239.255.76.67:7798?ttl=0'
ticks=$(getconf CLK_TCK)
# CPU seconds (user + system) a running process has used so far.
cpu_of() { awk -v t="$ticks" '{print ($14 + $15) / t}' "/proc/$1/stat"; }

"$build/server/covtrackd" --config "$config" --lcm-url "$url" --log-level warn &
pid=$!
sleep "$seconds"
daemon=$(cpu_of $pid)
kill -TERM $pid; wait $pid

"$build/tests/server/bench_raw_publish" "$url" 10 1000 "$seconds" &
pid=$!
sleep "$seconds"
raw=$(cpu_of $pid)
wait $pid

echo "$daemon $raw $seconds" | awk '{
  printf "covtrackd, 10 sensors x 1 kHz (+ truth, heartbeat): %.2f CPU s in %d s = %.1f%% of one core\n", $1, $3, 100*$1/$3
  printf "plain LCM publisher, the same 10 x 1 kHz poses:     %.2f CPU s in %d s = %.1f%% of one core\n", $2, $3, 100*$2/$3
  printf "ratio daemon / plain publisher: %.2f\n", $1/$2 }'
