"""A live subscription to the real covtrackd running config/sim.toml, inside the private
network namespace CTest starts these tests in (tests/netns_run.sh): names, covariances,
callbacks on the receiving thread, the GIL released while waiting, the graph fed live, and
the device reported unreachable when the daemon dies."""
import os
import signal
import subprocess
import sys
import threading
import time
import tomllib

import numpy as np
import pytest

import covtrack

pytestmark = pytest.mark.skipif(os.environ.get("COVTRACK_IN_NETNS") != "1",
                                reason="multicast: run inside tests/netns_run.sh (CTest does)")

WAIT_S = 10  # generous bounds on events that come within a second or so


@pytest.fixture(scope="module")
def config(source_dir):
    path = source_dir / "config" / "sim.toml"
    return path, tomllib.loads(path.read_text())


@pytest.fixture
def daemon(covtrackd, config):
    process = subprocess.Popen([str(covtrackd), "--config", str(config[0])],
                               stdout=subprocess.DEVNULL)  # its log goes to pytest's capture
    yield process
    if process.poll() is None:
        process.send_signal(signal.SIGTERM)
        process.wait(timeout=10)


def wait_until(condition, what):
    deadline = time.monotonic() + WAIT_S
    while not condition():
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.02)


def rotation_of(q):
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def check_pose(pose, device, sensor, parent, covariance):
    assert (pose.device, pose.sensor, pose.parent_frame, pose.child_frame) == (device, sensor, parent, sensor)
    assert pose.status in (covtrack.Status.OK, covtrack.Status.DEGRADED) and not pose.lost
    c = pose.covariance
    assert c.shape == (6, 6) and pose.position.shape == (3,) and pose.quaternion.shape == (4,)
    np.testing.assert_array_equal(c, c.T)
    assert np.all(np.linalg.eigvalsh(c) > 0)
    # BODY convention, as configured: the daemon sends the config's matrix unchanged.
    np.testing.assert_allclose(c, covariance, rtol=1e-12, atol=0)
    q = pose.quaternion
    assert abs(np.linalg.norm(q) - 1) < 1e-9 and q[0] >= 0
    m = pose.matrix
    np.testing.assert_allclose(m[:3, 3], pose.position)
    np.testing.assert_allclose(m[:3, :3], rotation_of(q), atol=1e-12)
    assert abs(pose.time_us - time.time() * 1e6) < 5e6


# The callbacks that raise on purpose are reported as unraisable exceptions.
@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_poses_covariances_callbacks_and_devices(daemon, config):
    _, cfg = config
    optical, magnetic = cfg["devices"]["optical"], cfg["devices"]["magnetic"]
    optical_cov = np.diag(np.square(optical["sigma_m"] + optical["sigma_rad"]))
    magnetic_cov = np.reshape(magnetic["covariance"], (6, 6))

    received, threads, lock = [], set(), threading.Lock()

    def on_head(pose):
        with lock:
            received.append(pose)
            threads.add(threading.get_ident())

    def broken(pose):
        raise RuntimeError("a broken callback")

    with covtrack.Subscriber() as s:
        s.on_pose(on_head, "optical/head")
        s.on_pose(broken, "magnetic/.*")

        head = s.wait_for("optical", "head", timeout_s=WAIT_S)
        assert head is not None, "no pose from covtrackd"
        check_pose(head, "optical", "head", "world", optical_cov)
        magnetic_pose = s.wait_for("magnetic", "s0", timeout_s=WAIT_S)
        assert magnetic_pose is not None
        check_pose(magnetic_pose, "magnetic", "s0", "magnetic_source", magnetic_cov)
        wait_until(lambda: len(received) >= 10, "10 callbacks")
        latest = s.latest("optical", "head")
        assert latest.sequence >= head.sequence

        with lock:
            sequences = [p.sequence for p in received]
            assert threading.get_ident() not in threads  # on the receiving thread
        assert all(p.device == "optical" and p.sensor == "head" for p in received)
        assert sequences == sorted(sequences)
        wait_until(lambda: s.callback_errors > 0, "the broken callback's error")
        # A raising callback costs nothing else: the streams go on.
        assert s.wait_for("magnetic", "s0", timeout_s=WAIT_S) is not None

        streams = {f"{st.device}/{st.sensor}": st for st in s.streams()}
        assert {"optical/head", "optical/wand", "magnetic/s0"} <= set(streams)
        assert streams["optical/head"].received >= 10 and streams["optical/head"].rejected == 0
        assert s.rejections() == {}

        wait_until(lambda: {"optical", "magnetic"} <= set(s.devices()), "heartbeats")
        device = s.devices()["optical"]
        assert device.reachable and device.state == "RUNNING" and device.driver == "sim"
        assert device.publishers == 1 and len(device.publishing) == 1
        assert device.publishing[0] == f"{device.host}/{device.pid}"
        assert device.second_publisher_warning == ""
    assert s.closed
    with pytest.raises(RuntimeError, match="closed"):
        s.latest("optical", "head")


def test_a_scene_graph_fed_live_gives_regions(daemon, source_dir):
    scene = covtrack.Scene(str(source_dir / "config" / "scenes" / "sim_lab.toml"))
    graph = scene.graph(live=True)
    with covtrack.Subscriber(streams="optical/.*") as s:
        assert all(not r.valid for r in scene.regions(graph=graph))  # LOST until reports come
        s.feed(graph)
        for device, sensor in scene.streams:
            assert s.wait_for(device, sensor, timeout_s=WAIT_S) is not None
        regions = {r.name: r for r in scene.regions(graph=graph)}
        assert list(regions) == scene.objects
        # The vase stands at the centre of the head's circle, always in view; the wand
        # goes round ahead of the head and is often beside or behind the camera.
        vase = regions["vase"]
        assert vase.valid and 0 < vase.assessment_px < 100 and len(vase.outer_px) >= 3
        for r in regions.values():
            assert r.valid or r.flags, f"{r.name}: no region, and no flag says why"
        T = graph.query("world", "head")
        np.testing.assert_allclose(T.position, s.latest("optical", "head").position, atol=0.05)


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_closing_from_a_callback_is_refused_and_a_dead_daemon_is_unreachable(daemon):
    with covtrack.Subscriber() as s:
        s.on_pose(lambda pose: s.close(), "optical/wand")
        assert s.wait_for("optical", "head", timeout_s=WAIT_S) is not None
        wait_until(lambda: s.callback_errors > 0, "the refused close")
        assert not s.closed
        wait_until(lambda: "optical" in s.devices(), "a heartbeat")
        daemon.kill()  # no goodbye: only the missing heartbeats tell
        daemon.wait()
        deadline = time.monotonic() + WAIT_S
        while True:
            pose = s.wait_for("optical", "head", timeout_s=max(0.0, deadline - time.monotonic()))
            assert pose is not None, "the stream was never reported LOST"
            if pose.device_unreachable:
                break
        assert pose.lost and np.all(np.isinf(np.diag(pose.covariance)))
        assert not s.devices()["optical"].reachable


def test_the_example_script_prints_the_streams(daemon, source_dir):
    run = subprocess.run([sys.executable, str(source_dir / "examples" / "python" / "print_poses.py"),
                          "--streams", "optical/.*", "--duration", "1.5"],
                         capture_output=True, text=True, timeout=30, env=os.environ)
    assert run.returncode == 0, run.stderr
    assert "optical/head" in run.stdout and "optical/wand" in run.stdout
    assert "magnetic" not in run.stdout
    assert " mm " in run.stdout and "reports" in run.stdout


def test_authenticated_daemon_and_keyed_and_plain_subscribers(covtrackd, covtrack_cli, config, tmp_path):
    key = tmp_path / "key"
    subprocess.run([str(covtrack_cli), "keygen", str(key)], check=True, capture_output=True)
    signed = tmp_path / "signed.toml"
    signed.write_text(f'[auth]\nkey_file = "{key}"\n\n' + config[0].read_text())
    process = subprocess.Popen([str(covtrackd), "--config", str(signed)], stdout=subprocess.DEVNULL)
    try:
        with covtrack.Subscriber(key_file=str(key)) as keyed, covtrack.Subscriber() as plain:
            assert plain.authentication() is None
            assert keyed.wait_for("optical", "head", timeout_s=WAIT_S) is not None
            assert plain.wait_for("optical", "head", timeout_s=WAIT_S) is not None
            counts = keyed.authentication()
            assert counts["authenticated"] > 0
            assert (counts["unauthenticated"], counts["forged"], counts["replayed"]) == (0, 0, 0)
            assert plain.rejections() == {} and keyed.rejections() == {}
        key.chmod(0o644)
        with pytest.raises(RuntimeError, match="others may read"):
            covtrack.Subscriber(key_file=str(key))
    finally:
        process.send_signal(signal.SIGTERM)
        process.wait(timeout=10)
