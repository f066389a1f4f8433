#!/usr/bin/env python3
"""Runs every command of the README's shell blocks as written, in order, block by block.

A command passes when it exits 0, or when it is still running after a few seconds (a
daemon, `echo`, a live view: it keeps running as a service for the rest of its block,
so that the commands after it see its streams). It fails when it exits with another
code. The commands run in a scratch folder that links the checkout's folders and the
build (the README's `build/`), inside the private network namespace and a virtual X
display this test is started in (CMake: netns_run.sh, with_xvfb.sh).
Skipped: tools/test.sh (this suite) and tools/demo.sh (setup and build, then the same
daemon and echo as the next block). The ```shell blocks (install into $HOME, a Debian
package with sudo) are not run here: sdk_install_test and deb_package_test run the same
commands into a scratch prefix and as root.
Usage: readme_commands_test.py BUILD_DIR SOURCE_DIR
"""
import os
import shlex
import shutil
import subprocess
import sys
import tempfile

# A refused flag, config or file ends a command within a second even on a loaded machine;
# the README has some 20 services and benchmarks, each waited for this long.
SERVICE_AFTER_S = 4.0
SKIPPED = {"tools/test.sh", "tools/demo.sh"}


def shell_blocks(readme):
    blocks, block, inside = [], None, False
    for line in open(readme, encoding="utf-8"):
        if line.startswith("```"):
            inside = not inside and line.strip() == "```sh"
            if inside:
                block = []
            elif block is not None:
                blocks.append(block)
                block = None
            continue
        if inside:
            block.append(line.rstrip("\n"))
    return blocks


def commands(block):
    """Logical commands: lines joined across backslashes and open quotes."""
    out, pending = [], ""
    for line in block:
        pending = f"{pending}\n{line}" if pending else line
        if pending.endswith("\\"):
            continue
        try:
            words = shlex.split(pending, comments=True)
        except ValueError:  # an open quote: the command goes on
            continue
        if words:
            out.append(pending)
        pending = ""
    return out


def main():
    build, src = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    work = tempfile.mkdtemp(prefix="covtrack_readme_")
    for name in os.listdir(src):
        if name not in ("build", ".git"):
            os.symlink(os.path.join(src, name), os.path.join(work, name))
    os.symlink(build, os.path.join(work, "build"))
    failures, ran = [], 0
    for block in shell_blocks(os.path.join(src, "README.md")):
        services = []
        for command in commands(block):
            if shlex.split(command, comments=True)[0] in SKIPPED:
                print(f"skip: {command}")
                continue
            ran += 1
            log = open(os.path.join(work, f"command_{ran}.txt"), "w+")
            proc = subprocess.Popen(["bash", "-c", command], cwd=work, stdout=log, stderr=subprocess.STDOUT,
                                    start_new_session=True)
            try:
                code = proc.wait(timeout=SERVICE_AFTER_S)
            except subprocess.TimeoutExpired:
                print(f"running: {command}")
                services.append(proc)
                continue
            log.seek(0)
            if code == 0:
                print(f"ok: {command}")
            else:
                failures.append(command)
                print(f"FAIL (exit {code}): {command}\n" + "".join(log.readlines()[-15:]))
        for proc in services:
            os.killpg(proc.pid, 15)
        for proc in services:
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, 9)
    print(f"{ran} commands run, {len(failures)} failed")
    if not failures:  # kept when something failed: each command's output is in it
        shutil.rmtree(work, ignore_errors=True)
    return 1 if failures or ran < 10 else 0


if __name__ == "__main__":
    sys.exit(main())
