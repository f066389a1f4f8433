"""What examples/read_log and pkgconfig_probe.cpp must print for a log, computed by the
Python module of the build tree (its own reading of the log, through covtrack.read_log).
Usage: expected_log_summary.py LOG read_log|probe"""
import sys

import numpy as np

import covtrack

log = covtrack.read_log(sys.argv[1])
if sys.argv[2] == "probe":
    print(f"{log.events} events, {sum(len(s) for s in log.poses.values())} poses")
    sys.exit()
for key, s in sorted(log.poses.items()):
    counts = [int(np.count_nonzero(s.status == k)) for k in range(3)]
    x, y, z = s.position[-1]
    line = (f"{key}: {counts[0]} ok {counts[1]} degraded {counts[2]} lost; last at {s.time_us[-1]} us: "
            f"[{x:.6f} {y:.6f} {z:.6f}] m in {s.parent_frame}")
    if s.status[-1] != 2:
        line += f", sigma x {np.sqrt(s.covariance[-1][0, 0]):.6f} m"
    print(line)
print(f"rejected {log.rejected_total}, damaged ranges {len(log.damage)}")
