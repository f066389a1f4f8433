#!/bin/sh
# The SDK as a user gets it: `cmake --install` of the build tree into a fresh prefix, the
# examples/ built out of tree against it (find_package(covtrack)), one file built with
# pkg-config alone, and the programs run from the prefix. Run inside a private network
# namespace (tests/netns_run.sh): the live examples subscribe to the installed covtrackd;
# and on an X server of its own (tests/with_xvfb.sh) for the 3-D example.
# Usage: sdk_install_test.sh BUILD_DIR SOURCE_DIR CMAKE CXX PYTHON   (PYTHONPATH: the build's module)
set -eu
build=$1 src=$2 cmake=$3 cxx=$4 python=$5
tmp=$(mktemp -d)
daemon=
cleanup() { [ -z "$daemon" ] || kill "$daemon" 2>/dev/null || true; rm -rf "$tmp"; }
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
prefix=$tmp/prefix

"$cmake" --install "$build" --prefix "$prefix" >"$tmp/install.log" || { cat "$tmp/install.log"; fail "cmake --install"; }
for f in bin/covtrackd bin/covtrack bin/covtrack-vision include/covtrack/pose_cov_t.hpp \
         include/covtrack/client/subscriber.hpp include/covtrack/lcmlog/log_reader.hpp; do
  [ -f "$prefix/$f" ] || fail "not installed: $f"
done

# The unit and config installed with the programs name them where they are.
unit=$prefix/lib/systemd/system/covtrackd.service
grep -qx "ExecStart=$prefix/bin/covtrackd --config $prefix/etc/covtrack/covtrackd.toml" "$unit" \
  || fail "ExecStart in $unit: $(grep ExecStart "$unit")"
"$prefix/bin/covtrackd" --config "$prefix/etc/covtrack/covtrackd.toml" --check || fail "installed config does not check"

# examples/ against the prefix only.
"$cmake" -S "$src/examples" -B "$tmp/examples" -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_BUILD_TYPE=Release >"$tmp/configure.log" 2>&1 \
  || { cat "$tmp/configure.log"; fail "configuring examples/"; }
grep -q "^covtrack_DIR:PATH=$prefix/" "$tmp/examples/CMakeCache.txt" || fail "covtrack found outside $prefix"
"$cmake" --build "$tmp/examples" -j2 >"$tmp/build.log" 2>&1 || { cat "$tmp/build.log"; fail "building examples/"; }

# The 3-D overlay (covtrack::osg) when the SDK has it: drawn off screen on the test's X
# server (tests/with_xvfb.sh), the crate covering part of the picture.
if [ -f "$prefix/lib/cmake/covtrack/covtrackOsgTargets.cmake" ]; then
  [ -x "$tmp/examples/ar_overlay" ] || fail "covtrack::osg installed but examples/ar_overlay not built"
  "$tmp/examples/ar_overlay" "$tmp/overlay.ppm" >"$tmp/overlay.txt" 2>&1 || { cat "$tmp/overlay.txt"; fail "ar_overlay"; }
  drawn=$(sed -n 's/^crate: outer region [0-9]* corners, inner [0-9]*, \([0-9]*\) pixels drawn over the video$/\1/p' "$tmp/overlay.txt")
  [ "${drawn:-0}" -gt 3000 ] || { cat "$tmp/overlay.txt"; fail "ar_overlay drew too little of the crate"; }
  [ "$(head -c 15 "$tmp/overlay.ppm" | tr '\n' ' ')" = "P6 640 480 255 " ] || fail "ar_overlay's image is not 640x480"
fi

# read_log on a recorded session and on a truncated copy, against the Python module's reading.
log=$src/tests/data/lenz_session.lcm
head -c "$(($(wc -c <"$log") - 10))" "$log" >"$tmp/truncated.lcm"
for l in "$log" "$tmp/truncated.lcm"; do
  "$tmp/examples/read_log" "$l" >"$tmp/got.txt" || fail "read_log $l"
  "$python" "$src/tests/sdk/expected_log_summary.py" "$l" read_log >"$tmp/want.txt"
  diff "$tmp/want.txt" "$tmp/got.txt" || fail "read_log $l differs from covtrack.read_log (- want, + got)"
  grep -q " ok " "$tmp/got.txt" || fail "read_log found no stream in $l"
done
grep -q "damaged ranges 1" "$tmp/got.txt" || fail "read_log did not report the truncation"

# One file, pkg-config alone.
PKG_CONFIG_PATH=$(dirname "$(find "$prefix" -name covtrack.pc)") pkg-config --cflags --libs covtrack >"$tmp/pc.txt" \
  || fail "pkg-config covtrack"
# shellcheck disable=SC2046
"$cxx" -std=c++23 "$src/tests/sdk/pkgconfig_probe.cpp" $(cat "$tmp/pc.txt") -o "$tmp/probe" || fail "pkg-config build"
"$tmp/probe" "$log" >"$tmp/got.txt" || fail "probe"
"$python" "$src/tests/sdk/expected_log_summary.py" "$log" probe >"$tmp/want.txt"
diff "$tmp/want.txt" "$tmp/got.txt" || fail "probe differs from covtrack.read_log"

# Live: the installed daemon with the demo's config; the examples run for a fixed time each.
"$prefix/bin/covtrackd" --config "$src/config/sim.toml" --log-level warn &
daemon=$!
"$tmp/examples/print_poses" 'optical/.*' 3 >"$tmp/poses.txt" || fail "print_poses"
grep -q '^optical/head OK in world: .* sigma xyz \[0.50 0.50 1.00\] mm' "$tmp/poses.txt" \
  || { cat "$tmp/poses.txt"; fail "print_poses printed no optical/head pose with the config's sigmas"; }
"$tmp/examples/camera_regions" 3 >"$tmp/regions.txt" || fail "camera_regions"
grep -q '^frame [0-9]*: outer [0-9]* corners' "$tmp/regions.txt" \
  || { cat "$tmp/regions.txt"; fail "camera_regions printed no region"; }
"$prefix/bin/covtrack" echo 'optical/head' --json --count 3 --duration 20 >"$tmp/echo.txt" || fail "covtrack echo"
[ "$(grep -c '"sensor":"head"' "$tmp/echo.txt")" -eq 3 ] || { cat "$tmp/echo.txt"; fail "installed covtrack echo"; }
echo "sdk_install_test: ok"
