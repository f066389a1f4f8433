#!/usr/bin/env bash
# The shipped examples fit together: each scene that names streams, viewed live against
# the config it says it fits, gets reports on every one of them and none refused for a
# frame mismatch. The one pair that does not fit (head_and_world.toml, an offline scene
# whose head hangs under tracker_base, against sim.toml, which reports it in world) must
# be told with both frame names. Run inside a private network namespace (multicast).
# (That every config passes `covtrackd --check` and every scene loads is
# shipped_configs_test.sh.)
# Usage: shipped_examples_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1 src=$2
daemon=$build/server/covtrackd cli=$build/tools/covtrack/covtrack
work=$(mktemp -d)
pids=()
cleanup() { for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done; wait 2>/dev/null || true; rm -rf "$work"; }
trap cleanup EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# Waits (on messages, up to 60 s) until every stream has reported once.
wait_for_streams() {
  for stream in "$@"; do
    "$cli" echo "$stream" --count 1 --duration 60 >/dev/null 2>&1 || true
  done
}

# view_live SCENE: 2 s of the live view into a PNG; its stderr (refusals and the
# per-stream summary) into $work/view.txt.
view_live() {
  "$cli" view "$1" --live --png "$work/view.png" --duration 2 >/dev/null 2>"$work/view.txt" ||
    fail "view $1 --live failed: $(cat "$work/view.txt")"
}

# fits CONFIG SCENE: every stream the scene names reports, and none is refused.
fits() {
  local config=$1 scene=$2
  mapfile -t streams < <(sed -n 's/^stream = "\(.*\)"/\1/p' "$scene")
  "$daemon" --config "$config" >"$work/daemon.txt" 2>&1 &
  pids+=($!)
  wait_for_streams "${streams[@]}"
  view_live "$scene"
  kill "${pids[-1]}"; wait "${pids[-1]}" 2>/dev/null || true
  if grep -q "reports its pose relative to frame" "$work/view.txt"; then
    fail "$scene against $config: $(grep 'relative to frame' "$work/view.txt")"
  fi
  for stream in "${streams[@]}"; do
    grep -Eq "^covtrack view: $stream: received [1-9]" "$work/view.txt" ||
      fail "$scene against $config: no reports on $stream ($(grep -c received "$work/view.txt") streams seen)"
  done
  echo "fits: $(basename "$config") + $(basename "$scene"): ${streams[*]}"
}

fits "$src/config/sim.toml" "$src/config/scenes/sim_lab.toml"
if [[ -d $src/build/fiducial_demo ]]; then fits "$src/config/fiducial.toml" "$src/config/scenes/toolbox.toml"; fi
"$cli" emulate-6dof --protocol fastrak --link /tmp/covtrack-fastrak --stations 1,2 --reset-time-s 1 --no-truth \
  >"$work/emulator.txt" 2>&1 &
pids+=($!)
for _ in $(seq 1 600); do [[ -e /tmp/covtrack-fastrak ]] && break; "$cli" echo --duration 0.1 >/dev/null 2>&1 || true; done
fits "$src/config/fastrak_emulated.toml" "$src/config/scenes/fixed_camera_tracked_tool.toml"

# The pair that does not fit is told, with both frame names, and its stream not used.
"$daemon" --config "$src/config/sim.toml" >"$work/daemon.txt" 2>&1 &
pids+=($!)
wait_for_streams optical/head
view_live "$src/config/scenes/head_and_world.toml"
grep -q "stream optical/head reports its pose relative to frame 'world', but the graph attaches it to frame 'tracker_base'" \
  "$work/view.txt" || fail "head_and_world.toml against sim.toml: the frame mismatch was not told: $(cat "$work/view.txt")"

if ((failures)); then echo "$failures failure(s)"; exit 1; fi
echo "all shipped examples fit"
