#!/bin/sh
# Runs a command inside a fresh private network namespace whose only interface is
# loopback, with multicast routed through it: LCM's udpm traffic cannot leave it.
# Usage: tests/netns_run.sh COMMAND [ARGS...]   (re-executes itself under unshare)
set -e
if [ "$COVTRACK_IN_NETNS" != 1 ]; then
  COVTRACK_IN_NETNS=1 exec unshare --net --map-root-user "$0" "$@"
fi
ip link set lo up
ip link set lo multicast on
ip route replace 224.0.0.0/4 dev lo  # replace: run again inside its own namespace, it is there already
exec "$@"
