"""The helper scripts in tools/: shellcheck-clean, and tools/build_ready.sh refuses a directory
that is not a Ready checkout with one line and exit 1, before it installs or builds anything."""
import glob
import os
import shutil
import subprocess

import pytest

SOURCE = os.environ.get("MORPHOGEN_SOURCE_DIR",
                        os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
SCRIPTS = sorted(glob.glob(os.path.join(SOURCE, "tools", "*.sh")))


def test_scripts_present():
    names = {os.path.basename(s) for s in SCRIPTS}
    assert {"build_petsc_cuda.sh", "build_ready.sh"} <= names


@pytest.mark.parametrize("script", SCRIPTS, ids=os.path.basename)
def test_shellcheck(script):
    shellcheck = shutil.which("shellcheck")
    if shellcheck is None:
        pytest.skip("shellcheck is not installed")
    res = subprocess.run([shellcheck, "-s", "bash", script], capture_output=True, text=True)
    assert res.returncode == 0, res.stdout + res.stderr


def test_build_ready_refuses_a_non_ready_directory(tmp_path):
    build = tmp_path / "build"
    res = subprocess.run(["bash", os.path.join(SOURCE, "tools", "build_ready.sh"), str(tmp_path),
                          str(build)], capture_output=True, text=True, timeout=60)
    assert res.returncode == 1, res.stdout + res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and "not a Ready checkout" in lines[0] and str(tmp_path) in lines[0]
    assert not build.exists()


def test_build_ready_needs_a_source_argument():
    res = subprocess.run(["bash", os.path.join(SOURCE, "tools", "build_ready.sh")],
                         capture_output=True, text=True, timeout=60)
    assert res.returncode != 0 and "usage: tools/build_ready.sh" in res.stderr
