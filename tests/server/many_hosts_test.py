#!/usr/bin/env python3
"""Three hosts on one Ethernet segment: two daemons, three clients, multicast with ttl=1.

Each host is a network namespace joined to a bridge (the switch) by a veth pair; host 1
and host 2 run a daemon of 10 simulated sensors at 500 Hz (10 kHz in all), and every host
runs `covtrack echo`. Phases, each a fresh client on every host connected at the time:
  all up             every client sees all 20 streams, nothing lost
  cable pulled       host 2's switch port down: hosts 1 and 3 keep host 1's streams,
                     nothing lost; host 2 still sees its own daemon
  back               all 20 streams everywhere again, nothing lost
  interface down     host 2 takes its own interface down (its routes go with it): its
                     daemon's sends fail; it must keep running and say so
  back               interface and multicast route restored: all 20 streams everywhere

Usage: many_hosts_test.py BUILD_DIR   (re-executes itself in a user and network namespace)
"""
import json
import os
import re
import signal
import subprocess
import sys
import tempfile
import time

SENSORS = 10
RATE_HZ = 500
URL = "udpm://239.255.76.67:7667?ttl=1"
PHASE_S = 4.0
HOSTS = (1, 2, 3)
DAEMONS = {1: "alpha", 2: "bravo"}  # host -> device name
SKIP = 77  # ctest's SKIP_RETURN_CODE: this kernel cannot make veth pairs or bridges here


def run(*cmd, check=True):
    result = subprocess.run(cmd, capture_output=True, text=True)
    if check and result.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: exit {result.returncode}: {result.stderr.strip()}")
    return result


class Segment:
    """The switch (this namespace's bridge) and one namespace per host, each held open by a sleeper."""

    def __init__(self):
        self.holders = {}
        run("ip", "link", "set", "lo", "up")
        if run("ip", "link", "add", "switch", "type", "bridge", check=False).returncode != 0:
            print("SKIP: cannot create a bridge in a user namespace on this kernel")
            sys.exit(SKIP)
        run("ip", "link", "set", "switch", "up")
        for h in HOSTS:
            holder = subprocess.Popen(["unshare", "--net", "sleep", "infinity"])
            self.holders[h] = holder
            # The namespace exists once the sleeper runs in it (its net namespace differs from ours).
            deadline = time.monotonic() + 10
            while os.readlink(f"/proc/{holder.pid}/ns/net") == os.readlink("/proc/self/ns/net"):
                if time.monotonic() > deadline:
                    raise RuntimeError(f"host {h}: no namespace after 10 s")
                time.sleep(0.01)
            run("ip", "link", "add", f"port{h}", "type", "veth", "peer", "name", "eth0", "netns", str(holder.pid))
            run("ip", "link", "set", f"port{h}", "master", "switch", "up")
            self.host(h, "ip", "link", "set", "lo", "up")
            self.host(h, "ip", "addr", "add", f"10.99.0.{h}/24", "dev", "eth0")
            self.connect(h)

    def command(self, h, *cmd):
        return ["nsenter", "-t", str(self.holders[h].pid), "-n", "--", *cmd]

    def host(self, h, *cmd):
        return run(*self.command(h, *cmd))

    def connect(self, h):
        """The host's interface up with the multicast route a network manager would add."""
        self.host(h, "ip", "link", "set", "eth0", "up")
        self.host(h, "ip", "route", "replace", "224.0.0.0/4", "dev", "eth0")

    def close(self):
        for holder in self.holders.values():
            holder.kill()
            holder.wait()


def start_daemon(segment, h, workdir):
    config = os.path.join(workdir, f"host{h}.toml")
    with open(config, "w") as f:
        f.write(f'[daemon]\nlcm_url = "{URL}"\nheartbeat_hz = 4\n\n[devices.{DAEMONS[h]}]\ntype = "sim"\n'
                f"sensor_count = {SENSORS}\nrate_hz = {RATE_HZ}\nseed = {h}\n"
                f"sigma_m = [0.001, 0.001, 0.002]\nsigma_rad = [0.002, 0.002, 0.004]\n")
    log = open(os.path.join(workdir, f"host{h}.log"), "w+")
    daemon = subprocess.Popen(segment.command(h, f"{BUILD}/server/covtrackd", "--config", config),
                              stdout=log, stderr=subprocess.STDOUT)
    return daemon, log


STREAM = re.compile(r"^covtrack echo: (\w+)/(s\d+): received (\d+), lost (\d+), rejected (\d+)", re.M)


def echo_everywhere(segment, hosts, seconds):
    """Streams each host's client saw in `seconds`: {host: {"device/sensor": (received, lost, rejected)}}."""
    clients = {h: subprocess.Popen(segment.command(h, f"{BUILD}/tools/covtrack/covtrack", "echo", "-u", URL,
                                                   "-d", str(seconds)),
                                   stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
               for h in hosts}
    seen = {}
    for h, client in clients.items():
        _, err = client.communicate(timeout=seconds + 60)
        if client.returncode != 0:
            raise RuntimeError(f"host {h}: covtrack echo exit {client.returncode}: {err}")
        seen[h] = {f"{d}/{s}": (int(r), int(l), int(j)) for d, s, r, l, j in STREAM.findall(err)}
    return seen


def streams_of(device):
    return {f"{device}/s{i}" for i in range(SENSORS)}


failures = []


def expect(phase, seen, wanted):
    """wanted: {host: set of devices}; each client must see exactly those devices' streams, none lost."""
    for h, devices in wanted.items():
        expected = set().union(*(streams_of(d) for d in devices))
        got = {key for key, (received, _, _) in seen[h].items() if received > 0}
        if got != expected:
            failures.append(f"{phase}: host {h} saw {sorted(got)}, expected {sorted(expected)}")
        for key, (received, lost, rejected) in sorted(seen[h].items()):
            if lost or rejected:
                failures.append(f"{phase}: host {h} {key}: received {received}, lost {lost}, rejected {rejected}")
        total = sum(received for received, _, _ in seen[h].values())
        print(f"{phase}: host {h}: {len(got)} streams, {total / PHASE_S:.0f} messages/s, "
              f"lost {sum(lost for _, lost, _ in seen[h].values())}")


def expect_outage_logged(logs):
    """Host 2's daemon says once that it cannot send and once that it sends again; host 1's says nothing."""
    for h, log in logs.items():
        cannot, again = log.count("cannot publish"), log.count("publishing again")
        wanted = (1, 1) if h == 2 else (0, 0)
        if (cannot, again) != wanted:
            failures.append(f"host {h}: covtrackd logged 'cannot publish' {cannot} and 'publishing again' {again} "
                            f"times, expected {wanted[0]} and {wanted[1]}")


class Watcher:
    """A client on host 3 that stays across an outage of host 2, following one of host 2's streams."""

    def __init__(self, segment, workdir, name):
        self.path = os.path.join(workdir, f"{name}.jsonl")
        self.out = open(self.path, "w")
        self.client = subprocess.Popen(segment.command(3, f"{BUILD}/tools/covtrack/covtrack", "echo", "--json",
                                                       "-u", URL, "bravo/s0"),
                                       stdout=self.out, stderr=subprocess.DEVNULL)

    def messages(self):
        with open(self.path) as f:
            return [json.loads(line) for line in f if line.endswith("\n")]

    def wait_for(self, what, condition):
        """Waits until the messages so far satisfy `condition` (60 s at most)."""
        deadline = time.monotonic() + 60
        while not condition(self.messages()):
            if time.monotonic() > deadline or self.client.poll() is not None:
                last = [(m["sequence"], m["status"], m["device_unreachable"]) for m in self.messages()[-3:]]
                raise RuntimeError(f"host 3 watching bravo/s0: {what} did not happen (last: {last})")
            time.sleep(0.05)

    def stop(self):
        self.client.send_signal(signal.SIGTERM)
        self.client.wait(timeout=30)
        self.out.close()


def unreachable(m):
    return m["device_unreachable"] and m["status"] == "LOST"


def outage(segment, workdir, name, leave, come_back, wanted):
    """Host 2 leaves; hosts 1 and 3 keep host 1's streams; a client on host 3 that stays sees
    host 2's streams LOST (no heartbeat) and then back, with later sequence numbers."""
    watcher = Watcher(segment, workdir, name)
    try:
        # A second of messages: heartbeats (4 Hz) have come too, without which a device
        # cannot be told unreachable.
        watcher.wait_for("a second of messages", lambda ms: len(ms) >= RATE_HZ)
        leave()
        expect(name, echo_everywhere(segment, wanted.keys(), PHASE_S), wanted)
        watcher.wait_for("LOST when host 2 left", lambda ms: any(map(unreachable, ms)))
        come_back()
        watcher.wait_for("back after host 2 returned",
                         lambda ms: any(unreachable(a) and b["status"] == "OK" and b["sequence"] > a["sequence"]
                                        for a, b in zip(ms, ms[1:])))
    finally:
        watcher.stop()


def wait_until_both_daemons_seen(segment, daemons):
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        for h, (daemon, _) in daemons.items():
            if daemon.poll() is not None:
                raise RuntimeError(f"host {h}: covtrackd ended (exit {daemon.returncode})")
        seen = echo_everywhere(segment, [3], 0.5)[3]
        if all(any(k.startswith(d + "/") for k in seen) for d in DAEMONS.values()):
            return
    raise RuntimeError("host 3 did not see both daemons within 60 s")


def main():
    segment = Segment()
    daemons = {}
    logs = {}
    with tempfile.TemporaryDirectory() as workdir:
        try:
            for h in DAEMONS:
                daemons[h] = start_daemon(segment, h, workdir)
            wait_until_both_daemons_seen(segment, daemons)
            every = set(DAEMONS.values())
            expect("all up", echo_everywhere(segment, HOSTS, PHASE_S), {h: every for h in HOSTS})

            outage(segment, workdir, "cable pulled", lambda: run("ip", "link", "set", "port2", "down"),
                   lambda: run("ip", "link", "set", "port2", "up"), {1: {"alpha"}, 2: {"bravo"}, 3: {"alpha"}})
            wait_until_both_daemons_seen(segment, daemons)
            expect("back", echo_everywhere(segment, HOSTS, PHASE_S), {h: every for h in HOSTS})

            outage(segment, workdir, "interface down", lambda: segment.host(2, "ip", "link", "set", "eth0", "down"),
                   lambda: segment.connect(2), {1: {"alpha"}, 3: {"alpha"}})
            wait_until_both_daemons_seen(segment, daemons)
            expect("back again", echo_everywhere(segment, HOSTS, PHASE_S), {h: every for h in HOSTS})

            for h, (daemon, log) in daemons.items():
                if daemon.poll() is not None:
                    failures.append(f"host {h}: covtrackd ended (exit {daemon.returncode}) while the network changed")
        finally:
            for h, (daemon, log) in daemons.items():
                if daemon.poll() is None:
                    daemon.send_signal(signal.SIGTERM)
                    daemon.wait(timeout=30)
                log.seek(0)
                logs[h] = log.read()
                print(f"host {h} covtrackd, exit {daemon.returncode}:\n  " + "\n  ".join(logs[h].splitlines()[:20]))
            segment.close()
    expect_outage_logged(logs)
    if failures:
        print("FAILED:\n  " + "\n  ".join(failures))
        return 1
    print("ok")
    return 0


if __name__ == "__main__":
    BUILD = os.path.abspath(sys.argv[1])
    if os.environ.get("COVTRACK_MANY_HOSTS_NS") != "1":
        os.environ["COVTRACK_MANY_HOSTS_NS"] = "1"
        os.execvp("unshare", ["unshare", "--net", "--map-root-user", sys.executable, *sys.argv])
    sys.exit(main())
