#!/usr/bin/env python3
"""Prints covtrack's live streams once a second: each stream's position, its 1-sigma
position and angle errors from the covariance, its status and the age of its last report.

    PYTHONPATH=build/client/python examples/python/print_poses.py --streams 'optical/.*'

(Once installed with `cmake --install`, no PYTHONPATH is needed.) Ctrl-C ends it.
"""
import argparse
import time

import numpy as np

import covtrack


def sigma_mm_deg(pose):
    """The largest 1-sigma position error (mm) and angle error (degrees) of a report."""
    if pose.lost:
        return float("inf"), float("inf")
    c = pose.covariance  # BODY convention: [tx ty tz rx ry rz]
    position = np.sqrt(np.linalg.eigvalsh(c[:3, :3]).max()) * 1e3
    angle = np.degrees(np.sqrt(np.linalg.eigvalsh(c[3:, 3:]).max()))
    return position, angle


def print_table(subscriber, reports):
    now_us = time.time() * 1e6
    for stream in subscriber.streams():
        pose = stream.latest
        if pose is None:
            continue
        x, y, z = pose.position
        sp, sa = sigma_mm_deg(pose)
        print(f"{stream.device}/{stream.sensor:<10} {pose.status.name:<8} "
              f"[{x:+.3f} {y:+.3f} {z:+.3f}] m  sigma {sp:6.2f} mm {sa:5.2f} deg  "
              f"age {(now_us - pose.time_us) / 1e3:6.1f} ms  {reports.get(stream.device + '/' + stream.sensor, 0)} reports"
              f"{'  (device unreachable)' if pose.device_unreachable else ''}")
    for name, device in subscriber.devices().items():
        if not device.reachable:
            print(f"device {name}: UNREACHABLE")
    print(flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lcm-url", default=None, help="LCM URL (default: $LCM_DEFAULT_URL or LCM's)")
    parser.add_argument("--streams", default=".*", help="regular expression over device/sensor")
    parser.add_argument("--duration", type=float, default=None, help="stop after this many seconds")
    args = parser.parse_args()

    reports = {}

    def count(pose):  # runs on the subscriber's thread, with the GIL held: keep it short
        key = f"{pose.device}/{pose.sensor}"
        reports[key] = reports.get(key, 0) + 1

    end = None if args.duration is None else time.monotonic() + args.duration
    with covtrack.Subscriber(lcm_url=args.lcm_url, streams=args.streams) as subscriber:
        subscriber.on_pose(count)
        try:
            while end is None or time.monotonic() < end:
                time.sleep(1.0 if end is None else max(0.0, min(1.0, end - time.monotonic())))
                print_table(subscriber, dict(reports))
        except KeyboardInterrupt:
            pass
        rejected = subscriber.rejections()
        if rejected:
            print(f"rejected messages: {rejected}")


if __name__ == "__main__":
    main()
