"""covtrack.read_log on the shipped Lenz session (recorded by `covtrack record`,
tools/record_lenz_session.sh), checked against an independent reading of the file."""
import collections
import os

import numpy as np
import pytest

import covtrack
import lcm_log_format


def expected_poses(path):
    """{'device/sensor': [(log time, fields), ...]} read without covtrack."""
    streams = collections.defaultdict(list)
    for _offset, timestamp, channel, payload in lcm_log_format.events(path.read_bytes()):
        if channel.startswith("covtrack/pose/"):
            streams[channel[len("covtrack/pose/"):]].append((timestamp, lcm_log_format.pose_fields(payload)))
    return streams


def test_every_pose_stream_as_arrays(source_dir):
    path = source_dir / "tests" / "data" / "lenz_session.lcm"
    expected = expected_poses(path)
    log = covtrack.read_log(str(path))

    assert not log.damage and log.rejected_total == 0
    assert sorted(log.poses) == sorted(expected) and expected
    for key, rows in expected.items():
        stream = log.poses[key]
        n = len(rows)
        assert len(stream) == n
        assert f"{stream.device}/{stream.sensor}" == key
        assert (stream.parent_frame, stream.child_frame) == (rows[0][1]["parent_frame"], rows[0][1]["child_frame"])
        assert stream.time_us.shape == (n,) and stream.time_us.dtype == np.int64
        assert stream.position.shape == (n, 3) and stream.quaternion.shape == (n, 4)
        assert stream.covariance.shape == (n, 6, 6) and stream.status.shape == (n,)
        np.testing.assert_array_equal(stream.log_time_us, [t for t, _ in rows])
        np.testing.assert_array_equal(stream.time_us, [f["measurement_time_us"] for _, f in rows])
        np.testing.assert_array_equal(stream.publish_time_us, [f["publish_time_us"] for _, f in rows])
        np.testing.assert_array_equal(stream.sequence, [f["sequence"] for _, f in rows])
        np.testing.assert_array_equal(stream.status, [f["status"] for _, f in rows])
        np.testing.assert_allclose(stream.position, [f["position"] for _, f in rows], rtol=0, atol=1e-12)
        # The wire sends w >= 0 and unit norm; read_log gives the same quaternion.
        np.testing.assert_allclose(stream.quaternion, [f["quaternion"] for _, f in rows], rtol=0, atol=1e-9)
        for i, (_, f) in enumerate(rows):
            if f["status"] == covtrack.Status.LOST.value:
                assert np.all(np.isinf(np.diag(stream.covariance[i])))
            else:
                assert f["convention"] == 0  # BODY on the wire: read_log gives it unchanged
                np.testing.assert_array_equal(stream.covariance[i], np.reshape(f["covariance"], (6, 6)))


def test_truth_streams_match_the_poses_devices(source_dir):
    log = covtrack.read_log(str(source_dir / "tests" / "data" / "lenz_session.lcm"))
    assert sorted(log.truth) == sorted(log.poses)
    for key, truth in log.truth.items():
        assert len(truth) > 0
        assert np.all(np.diff(truth.time_us) > 0)
        np.testing.assert_allclose(np.linalg.norm(truth.quaternion, axis=1), 1.0, atol=1e-12)
        assert not hasattr(truth, "covariance")


def test_a_missing_file_raises_oserror(tmp_path):
    with pytest.raises(OSError, match="none.lcm"):
        covtrack.read_log(str(tmp_path / "none.lcm"))


def test_a_fifo_is_refused_at_once(tmp_path):
    fifo = tmp_path / "session.lcm"
    os.mkfifo(fifo)
    with pytest.raises(OSError, match="not a regular file"):
        covtrack.read_log(str(fifo))
