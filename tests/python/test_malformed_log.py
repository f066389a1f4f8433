"""A damaged or hostile log never crashes Python: read_log skips damaged bytes (Log.damage),
leaves out bad messages counted by reason (Log.rejected), and keeps every good one."""
import random
import struct

import numpy as np
import pytest

import covtrack
import lcm_log_format as fmt


@pytest.fixture(scope="module")
def session(source_dir):
    """The first 200 events of the shipped session, and its pose events' indices."""
    data = (source_dir / "tests" / "data" / "lenz_session.lcm").read_bytes()
    events = [(t, c, p) for _o, t, c, p in fmt.events(data)][:200]
    poses = [i for i, (_t, c, _p) in enumerate(events) if c.startswith("covtrack/pose/")]
    assert len(poses) > 20
    return events, poses


def write(tmp_path, events, name="damaged.lcm", between=None):
    """A log of (timestamp, channel, payload) events; between = {index: bytes before it}."""
    parts = []
    for i, (t, c, p) in enumerate(events):
        parts.append((between or {}).get(i, b""))
        parts.append(fmt.event_bytes(t, c, p, i))
    path = tmp_path / name
    path.write_bytes(b"".join(parts))
    return str(path)


def rows(log):
    return sum(len(s) for s in log.poses.values())


def with_payload(events, index, change):
    """The events with event `index`'s payload changed by change(bytearray, fields)."""
    t, c, p = events[index]
    payload = bytearray(p)
    change(payload, fmt.pose_fields(p))
    return events[:index] + [(t, c, bytes(payload))] + events[index + 1:]


def test_clean_prefix_reads_whole(tmp_path, session):
    events, poses = session
    log = covtrack.read_log(write(tmp_path, events))
    assert rows(log) == len(poses) and not log.damage and log.rejected_total == 0


def test_garbage_between_events_is_skipped_and_located(tmp_path, session):
    events, poses = session
    garbage = (struct.pack(">I", fmt.SYNC) + b" not an event ") * 3  # false sync words
    path = write(tmp_path, events, between={10: garbage})
    log = covtrack.read_log(path)
    assert rows(log) == len(poses)
    assert len(log.damage) == 1
    offset = sum(len(fmt.event_bytes(t, c, p)) for t, c, p in events[:10])
    assert (log.damage[0].offset, log.damage[0].skipped_bytes, log.damage[0].truncated) == (offset, len(garbage), False)


def test_truncated_tail_loses_only_the_cut_event(tmp_path, session):
    events, poses = session
    last_pose = poses[-1]
    path = write(tmp_path, events[:last_pose + 1])
    data = open(path, "rb").read()
    open(path, "wb").write(data[:-40])
    log = covtrack.read_log(path)
    assert rows(log) == len(poses) - 1
    assert len(log.damage) == 1 and log.damage[0].truncated


@pytest.mark.parametrize("reason,change", [
    ("bad length", lambda b, f: b.__setitem__(slice(f["string_offsets"][0], f["string_offsets"][0] + 4), struct.pack(">i", 0))),
    ("bad length", lambda b, f: b.__setitem__(slice(f["string_offsets"][2], f["string_offsets"][2] + 4), struct.pack(">i", 0x7FFFFFFF))),
    ("wrong type", lambda b, f: b.__setitem__(0, b[0] ^ 0xFF)),
    ("invalid pose", lambda b, f: b.__setitem__(slice(f["quaternion_offset"], f["quaternion_offset"] + 8), struct.pack(">d", 2.0))),
])
def test_a_bad_message_is_counted_and_left_out(tmp_path, session, reason, change):
    events, poses = session
    victim = poses[5]
    key = events[victim][1][len("covtrack/pose/"):]
    clean = covtrack.read_log(write(tmp_path, events, "clean.lcm"))
    log = covtrack.read_log(write(tmp_path, with_payload(events, victim, change)))
    assert log.rejected == {reason: 1}, log.last_rejection
    assert key in log.last_rejection
    assert len(log.poses[key]) == len(clean.poses[key]) - 1
    assert rows(log) == len(poses) - 1


def test_a_message_on_another_streams_channel_is_refused(tmp_path, session):
    events, poses = session
    t, channel, payload = events[poses[3]]
    moved = events + [(t + 1, "covtrack/pose/train/elsewhere", payload)]
    log = covtrack.read_log(write(tmp_path, moved))
    assert log.rejected == {"wrong channel": 1}
    assert "train/elsewhere" not in log.poses


def test_not_a_log_and_an_empty_file(tmp_path):
    noise = tmp_path / "noise.lcm"
    noise.write_bytes(random.Random(1).randbytes(5000))
    log = covtrack.read_log(str(noise))
    assert not log.poses and log.events == 0
    assert sum(d.skipped_bytes for d in log.damage) == 5000
    empty = tmp_path / "empty.lcm"
    empty.write_bytes(b"")
    log = covtrack.read_log(str(empty))
    assert not log.poses and log.events == 0


def test_random_damage_never_crashes_nor_delivers_an_invalid_pose(tmp_path, session):
    events, _poses = session
    good = open(write(tmp_path, events[:60], "good.lcm"), "rb").read()
    rng = random.Random(18)
    path = tmp_path / "fuzz.lcm"
    delivered = 0
    for _ in range(300):
        data = bytearray(good)
        for _ in range(rng.randint(1, 8)):
            at = rng.randrange(len(data))
            data[at] = rng.randrange(256) if rng.random() < 0.7 else data[at] ^ (1 << rng.randrange(8))
        if rng.random() < 0.2:
            del data[rng.randrange(len(data)):]
        path.write_bytes(bytes(data))
        log = covtrack.read_log(str(path))
        for s in log.poses.values():
            delivered += len(s)
            ok = s.status != covtrack.Status.LOST.value
            np.testing.assert_allclose(np.linalg.norm(s.quaternion[ok], axis=1), 1.0, atol=1e-6)
            c = s.covariance[ok]
            assert np.all(np.isfinite(c))
            np.testing.assert_allclose(c, np.transpose(c, (0, 2, 1)), rtol=0, atol=1e-9)
            assert np.all(np.linalg.eigvalsh(c) > -1e-9)
            assert np.all(np.isinf(np.diagonal(s.covariance[~ok], axis1=1, axis2=2)))
    assert delivered > 0  # most messages survive a few flipped bytes
