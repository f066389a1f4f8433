#!/usr/bin/env python3
"""`covtrack view` and `covtrack ar` in their windows, driven by a real mouse and keyboard
(XTest, through xdotool) on the X server of tests/with_xvfb.sh: a click on the crate's
middle selects it, a click far from it selects nothing, `t` switches to direct
selection, `p` turns preselection off. Each is told on stdout; the test waits for it.

Usage: with_xvfb.sh window_selection_test.py BUILD_DIR SOURCE_DIR
"""
import json
import os
import queue
import subprocess
import sys
import tempfile
import threading

WAIT_S = 60  # for each line (a loaded machine starts a window slowly)


def select_in_window(covtrack, command, scene, middle):
    """Clicks and keys in `covtrack COMMAND scene`'s window; returns what it told."""
    title = f"covtrack {command}"
    view = subprocess.Popen([covtrack, command, scene], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    lines = queue.Queue()
    threading.Thread(target=lambda: [lines.put(line) for line in view.stdout], daemon=True).start()
    told = []

    def wait_for(text, within_s=WAIT_S):
        """Whether `text` came within `within_s`; raises after WAIT_S."""
        while True:
            try:
                line = lines.get(timeout=within_s)
            except queue.Empty:
                if within_s < WAIT_S:
                    return False
                raise AssertionError(f"no '{text}' from {title} within {WAIT_S} s; it said: {told}")
            told.append(line.rstrip())
            if text in line:
                return True

    try:
        window = subprocess.run(["timeout", str(WAIT_S), "xdotool", "search", "--sync", "--onlyvisible",
                                 "--name", title], check=True, capture_output=True, text=True).stdout.split()[0]

        def xdotool(*args):
            subprocess.run(["xdotool", *args], check=True)

        # The window shows the image 1:1 from its corner: window and image pixels agree.
        # A window can be visible before its program takes input: on a loaded machine the
        # 3-D view's first click was lost (nothing told in 60 s). Click again until it
        # answers; a second click on the crate selects it again, the same answer.
        for _ in range(WAIT_S // 2):
            xdotool("mousemove", "--window", window, str(middle[0]), str(middle[1]), "click", "1")
            if wait_for("selected crate (two-step)", within_s=2):
                break
        else:
            raise AssertionError(f"no 'selected crate (two-step)' from {title} within {WAIT_S} s; it said: {told}")
        xdotool("mousemove", "--window", window, "5", "5", "click", "1")
        wait_for("selected nothing")
        xdotool("mousemove", "--window", window, str(middle[0]), str(middle[1]))
        xdotool("key", "t")  # the X server's focus follows the pointer (no window manager)
        wait_for("selection: direct")
        xdotool("click", "1")
        wait_for("selected crate (direct)")
        xdotool("key", "p")
        wait_for("preselection: off")
    finally:
        view.terminate()
        view.wait(timeout=30)
    return told


def main(build, source):
    covtrack = os.path.join(build, "tools/covtrack/covtrack")
    with tempfile.TemporaryDirectory() as work:
        scene = os.path.join(work, "crate.toml")
        with open(scene, "w") as f:
            f.write(f'[camera]\nframe = "camera"\ncalibration = "{source}/config/cameras/rendered_640x480.yml"\n'
                    '[[transform]]\nparent = "camera"\nchild = "crate"\nposition_m = [0.02, -0.01, 0.5]\n'
                    'sigma_m = [0.003, 0.003, 0.003]\nsigma_rad = [0.01, 0.01, 0.01]\n'
                    '[[object]]\nname = "crate"\nframe = "crate"\nbox_m = [0.08, 0.06, 0.04]\n')
        regions = json.loads(subprocess.run([covtrack, "regions", scene, "--json"], check=True,
                                            capture_output=True, text=True).stdout)
        inner = regions["objects"][0]["inner_px"]
        middle = (round(sum(p[0] for p in inner) / len(inner)), round(sum(p[1] for p in inner) / len(inner)))

        for command in ("view", "ar"):
            told = select_in_window(covtrack, command, scene, middle)
            print(f"covtrack {command}:\n  " + "\n  ".join(told))
    print("ok")
    return 0


if __name__ == "__main__":
    sys.exit(main(os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])))
