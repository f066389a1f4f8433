#!/bin/sh
# `cpack -G DEB` as a user runs it, the packages installed into this machine with apt-get,
# checked from what they installed (the config as a conffile, the unit's command line, the
# daemon started from it in a private network namespace and heard by the installed
# `covtrack echo`, the Python module, a pkg-config build against /usr), then purged.
# Needs root: skipped (exit 77) otherwise, and when covtrack is already installed here.
# Usage: deb_package_test.sh BUILD_DIR SOURCE_DIR CXX CPACK
set -eu
build=$1 src=$2 cxx=$3 cpack=$4
skip() { echo "deb_package_test: skipped: $*"; exit 77; }
[ "$(id -u)" -eq 0 ] || skip "installing a package needs root"
command -v apt-get >/dev/null && command -v dpkg-shlibdeps >/dev/null || skip "needs apt-get and dpkg-dev"
for p in covtrack covtrack-dev; do
  ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'ok installed' || skip "$p is installed already; left alone"
done

tmp=$(mktemp -d)
installed=
cleanup() { [ -z "$installed" ] || dpkg --purge covtrack-dev covtrack >/dev/null 2>&1 || true; rm -rf "$tmp"; }
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

"$cpack" --config "$build/CPackConfig.cmake" -G DEB -B "$tmp/packages" >"$tmp/cpack.log" 2>&1 \
  || { cat "$tmp/cpack.log"; fail "cpack -G DEB"; }
deb=$(ls "$tmp"/packages/covtrack_*.deb) dev=$(ls "$tmp"/packages/covtrack-dev_*.deb) || fail "no packages: $(ls "$tmp/packages")"
dpkg-deb -f "$deb" Depends | grep -q 'liblcm1' || fail "Depends without the shared libraries: $(dpkg-deb -f "$deb" Depends)"
dpkg-deb -f "$deb" Depends | grep -q 'python3-numpy' || fail "Depends without python3-numpy"
[ "$(dpkg-deb -I "$deb" conffiles)" = /etc/covtrack/covtrackd.toml ] || fail "conffiles: $(dpkg-deb -I "$deb" conffiles)"

installed=1
DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "$deb" "$dev" >"$tmp/apt.log" 2>&1 \
  || { cat "$tmp/apt.log"; fail "apt-get install"; }
version=$(dpkg-deb -f "$deb" Version)
[ "$(/usr/bin/covtrackd --version)" = "covtrackd $version" ] || fail "covtrackd --version: $(/usr/bin/covtrackd --version)"
[ "$(/usr/bin/covtrack --version)" = "covtrack $version" ] || fail "covtrack --version: $(/usr/bin/covtrack --version)"
dpkg-query -W -f='${Conffiles}\n' covtrack | grep -q '/etc/covtrack/covtrackd.toml' || fail "config is no conffile"
cmp /etc/covtrack/covtrackd.toml "$src/config/sim.toml" || fail "/etc/covtrack/covtrackd.toml is not config/sim.toml"

unit=$(dpkg -L covtrack | grep '/systemd/system/covtrackd.service$') || fail "no covtrackd.service installed"
exec_start=$(sed -n 's/^ExecStart=//p' "$unit")
[ "$exec_start" = "/usr/bin/covtrackd --config /etc/covtrack/covtrackd.toml" ] || fail "ExecStart=$exec_start"
if command -v systemd-analyze >/dev/null; then
  systemd-analyze verify "$unit" || fail "systemd-analyze verify $unit"
fi
# shellcheck disable=SC2086
$exec_start --check || fail "$exec_start --check"

# The service's command line, in a namespace; SIGTERM must end it with status 0.
"$src/tests/netns_run.sh" sh -c "$exec_start --log-level warn & d=\$!
  /usr/bin/covtrack echo --json --count 5 --duration 30 >'$tmp/echo.txt'; e=\$?
  kill -TERM \$d; wait \$d; s=\$?; [ \$e -eq 0 ] && [ \$s -eq 0 ] || { echo \"echo \$e, daemon \$s\"; exit 1; }" \
  || fail "the installed daemon and covtrack echo"
[ "$(grep -c '"device"' "$tmp/echo.txt")" -eq 5 ] || { cat "$tmp/echo.txt"; fail "covtrack echo heard no 5 poses"; }

(cd / && env -u PYTHONPATH /usr/bin/python3 -c 'import covtrack; print(covtrack.__file__)') >"$tmp/py.txt" || fail "import covtrack"
grep -q '^/usr/lib/python3' "$tmp/py.txt" || fail "covtrack imported from $(cat "$tmp/py.txt")"

# covtrack-dev: one file against /usr alone (not /usr/local).
pc_dirs=/usr/lib/pkgconfig:/usr/share/pkgconfig:/usr/lib/$(dpkg-architecture -qDEB_HOST_MULTIARCH)/pkgconfig
# shellcheck disable=SC2046
"$cxx" -std=c++23 "$src/tests/sdk/pkgconfig_probe.cpp" $(PKG_CONFIG_LIBDIR=$pc_dirs pkg-config --cflags --libs covtrack) \
  -o "$tmp/probe" || fail "pkg-config build against covtrack-dev"
"$tmp/probe" "$src/tests/data/lenz_session.lcm" | grep -q '^[1-9][0-9]* events, [1-9][0-9]* poses$' || fail "probe"

dpkg --purge covtrack-dev covtrack >"$tmp/purge.log" 2>&1 || { cat "$tmp/purge.log"; fail "dpkg --purge"; }
installed=
for f in /usr/bin/covtrackd /etc/covtrack/covtrackd.toml "$unit"; do [ ! -e "$f" ] || fail "$f left behind"; done
echo "deb_package_test: ok"
