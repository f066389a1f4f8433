"""The Subscriber without traffic (LCM's in-process memq:// URL, so no network namespace
is needed): the GIL is released while waiting, mistakes are exceptions, close is final."""
import threading
import time

import pytest

import covtrack


def spins_during(action):
    """How often a pure-Python thread gets round its loop while `action` runs."""
    counter, stop = [0], threading.Event()

    def spin():
        while not stop.is_set():
            counter[0] += 1

    spinner = threading.Thread(target=spin)
    spinner.start()
    try:
        before = counter[0]
        action()
        return counter[0] - before
    finally:
        stop.set()
        spinner.join()


def test_waiting_releases_the_gil():
    with covtrack.Subscriber(lcm_url="memq://") as s:
        waiting = spins_during(lambda: s.wait_for("nobody", "here", timeout_s=0.3))
    sleeping = spins_during(lambda: time.sleep(0.3))
    # Held for the 0.3 s, the GIL would have frozen the other thread (a few percent of
    # what it does while this one sleeps: only the switches around the call).
    assert waiting > 0.3 * sleeping, (waiting, sleeping)


def test_mistakes_are_exceptions():
    with pytest.raises(ValueError, match="regular expression"):
        covtrack.Subscriber(lcm_url="memq://", streams="optical/(")
    with pytest.raises(ValueError, match="stale_after_s"):
        covtrack.Subscriber(lcm_url="memq://", stale_after_s=0)
    with pytest.raises(RuntimeError):
        covtrack.Subscriber(lcm_url="nonsense://")
    with covtrack.Subscriber(lcm_url="memq://") as s:
        with pytest.raises(TypeError):
            s.on_pose(42)
        with pytest.raises(ValueError, match="pattern"):
            s.on_pose(print, "(")
        with pytest.raises(ValueError, match="timeout_s"):
            s.wait_for("a", "b", timeout_s=-1)
        with pytest.raises(ValueError, match="timeout_s"):
            s.wait_for("a", "b", timeout_s=float("nan"))
        assert s.latest("a", "b") is None and s.streams() == [] and s.devices() == {}


def test_close_is_final_and_idempotent():
    s = covtrack.Subscriber(lcm_url="memq://")
    s.close()
    s.close()
    assert s.closed
    for call in (lambda: s.latest("a", "b"), lambda: s.wait_for("a", "b", 0.1), s.streams, lambda: s.on_pose(print)):
        with pytest.raises(RuntimeError, match="closed"):
            call()
