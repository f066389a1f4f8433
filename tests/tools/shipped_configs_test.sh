#!/usr/bin/env bash
# Every shipped daemon config passes `covtrackd --check`, every shipped Lenz track layout
# passes it through a lenz device that names it, and every shipped scene loads
# (`covtrack regions SCENE --json`). The files are found when the test runs, by what they
# hold, so a new one is covered without a change here: every TOML file under config/ and
# examples/ is a daemon config ([devices.*]), a track layout ([[sections]]) or a scene
# ([camera], [[transform]], [[object]]); a TOML file that is none of them fails the test.
# --check opens the files a config names (image sequences, video files, layouts, corner
# calibrations) but no device (serial port, camera, HID): a config for hardware checks
# on a machine without it. The files are checked from a scratch copy of config/ and
# examples/ beside a `build` link to BUILD_DIR, because the fiducial configs name the
# frames the build renders as ../build/fiducial_demo/... (targets fiducial_demo_frames
# and fiducial_bundle_demo_frames, built by default).
# Usage: shipped_configs_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$(realpath "$1") src=$(realpath "$2")
daemon=$build/server/covtrackd cli=$build/tools/covtrack/covtrack
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cp -r "$src/config" "$src/examples" "$work/"
ln -s "$build" "$work/build"

failures=0 checked=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
# run NAME COMMAND...: the command must exit 0; its output is shown when it does not.
run() {
  local name=$1; shift
  checked=$((checked + 1))
  if "$@" >"$work/out.txt" 2>&1; then echo "ok: $name"; else fail "$name (exit $?): $(cat "$work/out.txt")"; fi
}

# The table headers of a TOML file, one per line, e.g. "[devices.sim]" or "[[sections]]".
headers() { sed -n 's/^[[:space:]]*\(\[\[*[^]]*\]\]*\).*/\1/p' "$1"; }

while IFS= read -r file; do
  name=${file#"$work"/}
  if headers "$file" | grep -q '^\[devices\.'; then
    run "$name: covtrackd --check" "$daemon" --check --config "$file"
  elif headers "$file" | grep -qx '\[\[sections\]\]'; then
    printf '[devices.layout_check]\ntype = "lenz"\nport = "/dev/null"\nlayout = "%s"\n' "$file" >"$work/layout_check.toml"
    run "$name: covtrackd --check of a lenz device with this layout" \
      "$daemon" --check --config "$work/layout_check.toml"
  elif headers "$file" | grep -Eqx '\[camera\]|\[\[transform\]\]|\[\[object\]\]'; then
    run "$name: covtrack regions" "$cli" regions "$file" --json
  else
    fail "$name: neither a daemon config, a track layout nor a scene: nothing checks it"
  fi
done < <(find "$work/config" "$work/examples" -name '*.toml' | sort)

echo "$checked file(s) checked, $failures failure(s)"
((checked > 0)) || { echo "FAIL: no shipped file found under $src/config and $src/examples"; exit 1; }
((failures == 0))
