"""Shared helpers for the end-to-end tests: run the morphogen executable (optionally under
mpiexec) with a timeout, from a temporary directory."""
import os
import subprocess

import pytest

EXE = os.environ.get("MORPHOGEN_EXE", os.path.join(os.path.dirname(__file__), "../../build/morphogen"))
MPIEXEC = os.environ.get("MORPHOGEN_MPIEXEC", "mpiexec")
SOURCE = os.environ.get("MORPHOGEN_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "../.."))


def run(args, cwd, ranks=1, timeout=300, exe=EXE):
    cmd = [exe] + list(args)
    if ranks > 1:
        cmd = [MPIEXEC, "--oversubscribe", "-n", str(ranks)] + cmd
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    return subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=timeout, env=env)


def error_lines(proc):
    """Non-empty stderr lines of morphogen itself, warnings left out (mpiexec appends its own
    banner, framed by dashed lines, when a rank exits non-zero)."""
    lines = []
    for l in proc.stderr.splitlines():
        if l.startswith("-----"):
            break
        if l.strip() and not l.startswith("morphogen: warning:"):
            lines.append(l)
    return lines


@pytest.fixture
def workdir(tmp_path):
    return tmp_path
