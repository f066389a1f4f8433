#!/bin/sh
# Replay throughput: `covtrack replay --speed 0` against lcm-logplayer on the same log,
# both publishing on multicast inside a private network namespace (nothing leaves it).
# Usage: tests/tools/bench_replay.sh BUILD_DIR [EVENTS]     (run by hand; not in CTest)
set -e
build=${1:?usage: $0 BUILD_DIR [EVENTS]}
events=${2:-1000000}
here=$(cd "$(dirname "$0")" && pwd)
cli=$build/tools/covtrack/covtrack
[ -x "$cli" ] || cli=$build/tests/tools/covtrack_record_replay_cli
log=$(mktemp /tmp/covtrack-bench-XXXXXX.lcmlog)
trap 'rm -f "$log"' EXIT
"$build/tests/tools/bench_make_log" "$log" "$events"
url='udpm://239.255.76.67:7799?ttl=0'

# Wall time of a command in seconds (inside the namespace).
cat > "$log.run" <<'INNER'
#!/bin/sh
start=$(date +%s.%N); "$@" >/dev/null 2>&1 || true; end=$(date +%s.%N)
echo "$end - $start" | bc
INNER
chmod +x "$log.run"
trap 'rm -f "$log" "$log.run"' EXIT

ours=$("$here/../netns_run.sh" "$log.run" "$cli" replay --speed 0 --lcm-url "$url" "$log")
# lcm-logplayer has no "as fast as possible": a huge speed factor makes every wait zero.
theirs=$("$here/../netns_run.sh" "$log.run" lcm-logplayer -s 1000000000 --lcm-url="$url" "$log")
echo "log: $events events, $(stat -c %s "$log") bytes"
echo "covtrack replay --speed 0: $ours s, $(echo "$events / $ours" | bc) events/s"
echo "lcm-logplayer -s 1e9:      $theirs s, $(echo "$events / $theirs" | bc) events/s"
echo "ratio (covtrack / lcm-logplayer): $(echo "scale=2; $theirs / $ours" | bc)"
