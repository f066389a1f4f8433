"""An independent reading of LCM logs and covtrack pose messages, written from the formats'
descriptions (LCM's log format; protocol/lcmtypes/pose_cov_t.lcm with LCM's big-endian
encoding), to check covtrack.read_log against. Trusts its input: use it on good logs only."""
import struct

SYNC = 0xEDA1DA01


def events(data):
    """(offset, timestamp_us, channel, payload) of each event of a well-formed log."""
    at = 0
    while at < len(data):
        sync, _number, timestamp, channel_len, payload_len = struct.unpack_from(">IqqII", data, at)
        assert sync == SYNC
        start = at + 28
        channel = data[start:start + channel_len].decode()
        yield at, timestamp, channel, data[start + channel_len:start + channel_len + payload_len]
        at = start + channel_len + payload_len


def event_bytes(timestamp, channel, payload, number=0):
    """One log event, as LCM writes it."""
    name = channel.encode()
    return struct.pack(">IqqII", SYNC, number, timestamp, len(name), len(payload)) + name + payload


def pose_fields(payload):
    """The fields of a pose_cov_t message, and the offsets of its strings' length words."""
    at = 8  # the type fingerprint
    measurement, publish, sequence = struct.unpack_from(">qqq", payload, at)
    at += 24
    strings, string_offsets = [], []
    for _ in range(4):
        (n,) = struct.unpack_from(">i", payload, at)
        string_offsets.append(at)
        strings.append(payload[at + 4:at + 4 + n - 1].decode())
        at += 4 + n
    position = struct.unpack_from(">3d", payload, at)
    quaternion = struct.unpack_from(">4d", payload, at + 24)
    quaternion_offset = at + 24
    covariance = struct.unpack_from(">36d", payload, at + 56)
    convention, status = struct.unpack_from(">bb", payload, at + 56 + 288)
    return {
        "measurement_time_us": measurement, "publish_time_us": publish, "sequence": sequence,
        "device": strings[0], "sensor": strings[1], "parent_frame": strings[2], "child_frame": strings[3],
        "position": position, "quaternion": quaternion, "covariance": covariance,
        "convention": convention, "status": status,
        "string_offsets": string_offsets, "quaternion_offset": quaternion_offset,
    }
