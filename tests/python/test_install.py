"""`cmake --install` puts the module where Debian's python3 finds packages, and it works
from there, outside the build tree."""
import os
import pathlib
import subprocess
import sys

from conftest import BINARY_DIR

CMAKE = os.environ.get("COVTRACK_CMAKE", "cmake")
INSTALL_DIR = os.environ.get("COVTRACK_PYTHON_INSTALL_DIR", f"lib/python{sys.version_info.major}.{sys.version_info.minor}/dist-packages")


def test_the_install_folder_is_on_pythons_path_under_usr_local_and_usr():
    # What the interpreter searches without PYTHONPATH: an install to the default prefix
    # (/usr/local) or to /usr (a Debian package) is found by a plain `import covtrack`.
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    run = subprocess.run([sys.executable, "-c", "import sys; print('\\n'.join(sys.path))"],
                         capture_output=True, text=True, timeout=60, env=env)
    searched = run.stdout.split()
    for prefix in ("/usr/local", "/usr"):
        assert str(pathlib.Path(prefix) / INSTALL_DIR) in searched, (prefix, INSTALL_DIR, searched)


def test_installed_module_imports_and_reads_a_log(tmp_path, source_dir):
    prefix = tmp_path / "prefix"
    run = subprocess.run([CMAKE, "--install", str(BINARY_DIR), "--prefix", str(prefix), "--component", "python"],
                         capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, run.stdout + run.stderr
    site = prefix / INSTALL_DIR
    assert (site / "covtrack" / "__init__.py").is_file()
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["PYTHONPATH"] = str(site)
    log = source_dir / "tests" / "data" / "lenz_session.lcm"
    check = subprocess.run(
        [sys.executable, "-c",
         f"import covtrack; print(covtrack.__file__); print(len(covtrack.read_log({str(log)!r}).poses))"],
        capture_output=True, text=True, timeout=60, env=env, cwd=tmp_path)
    assert check.returncode == 0, check.stderr
    where, streams = check.stdout.split()
    assert pathlib.Path(where).is_relative_to(site) and int(streams) > 0
