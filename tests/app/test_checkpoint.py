"""Checkpoint/restart and snapshot output, end to end (1 and 2 ranks):
- restart equivalence: N steps straight == N/2, checkpoint, restart from `latest`, N/2 more,
  bitwise for the explicit and the splitting scheme on the same rank count;
- written on 1 rank and restarted on 2 (and the reverse): equal to 1e-12 relative;
- SIGUSR1 during a run: a complete checkpoint, exit code 3, and the restarted run ends in the
  same state as an uninterrupted one; -max_walltime does the same;
- a truncated checkpoint is refused with a clear error while the previous one loads, and
  `latest` skips it with a warning;
- a restart from an older checkpoint retires the newer ones and the series has no duplicates;
- the NaN guard names the last good checkpoint; a read-only or full output directory fails
  cleanly (exit 4, at start or mid-run) and leaves the previous checkpoint loadable;
- snapshots hold /VTKHDF/PointData on the cell centres (WholeExtent 0..n-1, Origin h/2);
  checkpoints of the CellData layout (an image of the cell corners: WholeExtent 0..n, Origin 0)
  still restart, bitwise, and the series index then describes both layouts as cell data.
Fields are compared with h5py (the VTKHDF datasets /VTKHDF/PointData/<species>, or CellData
in files of that layout)."""
import json
import os
import signal
import subprocess
import sys
import time

import h5py
import numpy as np
import pytest

from conftest import EXE, MPIEXEC, run

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from vtkhdf_layouts import to_celldata_layout  # noqa: E402

BASE = ["-grid_n", "48,40", "-png_every", "0", "-progress_every", "100000"]
SCHEMES = {"explicit": [], "split": ["-integrator", "split", "-dt", "2"]}


def fields(path):
    with h5py.File(path, "r") as f:
        g = f["VTKHDF/PointData"] if "VTKHDF/PointData" in f else f["VTKHDF/CellData"]
        return {k: g[k][...] for k in g}



def attrs(path):
    with h5py.File(path, "r") as f:
        return dict(f["morphogen"].attrs)


def ok(r):
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    return r


def error_line(r):
    lines = [l for l in r.stderr.splitlines() if l.startswith("morphogen:")]
    assert lines, r.stderr
    return lines[0]


@pytest.mark.parametrize("np_", [1, 2])
@pytest.mark.parametrize("scheme", SCHEMES)
def test_restart_is_bitwise(tmp_path, scheme, np_):
    opts = BASE + SCHEMES[scheme]
    ok(run(opts + ["-steps", "40", "-output_dir", "straight"], tmp_path, np_))
    ok(run(opts + ["-steps", "20", "-output_dir", "halves"], tmp_path, np_))
    r = ok(run(opts + ["-steps", "40", "-output_dir", "halves", "-restart", "latest"], tmp_path,
               np_))
    assert "restart from halves/checkpoint_0000020.vtkhdf: step 20" in r.stdout
    a = fields(tmp_path / "straight/checkpoint_0000040.vtkhdf")
    b = fields(tmp_path / "halves/checkpoint_0000040.vtkhdf")
    assert sorted(a) == ["a", "b"]
    for s in a:
        assert np.array_equal(a[s], b[s]), f"{s}: max diff {np.abs(a[s] - b[s]).max()}"
    at = attrs(tmp_path / "halves/checkpoint_0000040.vtkhdf")
    assert at["step"] == 40 and at["nranks"] == np_ and at["complete"] == 1


@pytest.mark.parametrize("ranks", [(1, 2), (2, 1)])
@pytest.mark.parametrize("scheme", SCHEMES)
def test_restart_on_other_rank_count(tmp_path, scheme, ranks):
    first, second = ranks
    opts = BASE + SCHEMES[scheme]
    if scheme == "split":  # 1 rank: CG+ICC, 2 ranks: CG+block-Jacobi ICC; solve to round-off
        opts += ["-diffusion_ksp_rtol", "1e-15", "-diffusion_ksp_atol", "1e-300"]
    ok(run(opts + ["-steps", "40", "-output_dir", "straight"], tmp_path, second))
    ok(run(opts + ["-steps", "20", "-output_dir", "halves"], tmp_path, first))
    r = ok(run(opts + ["-steps", "40", "-output_dir", "halves", "-restart", "latest"], tmp_path,
               second))
    assert f"written on {first} rank" in r.stdout
    a = fields(tmp_path / "straight/checkpoint_0000040.vtkhdf")
    b = fields(tmp_path / "halves/checkpoint_0000040.vtkhdf")
    for s in a:
        rel = np.abs(a[s] - b[s]).max() / np.abs(a[s]).max()
        assert rel <= 1e-12, f"{s}: relative difference {rel:.3e}"


def start(args, cwd, ranks):
    cmd = [EXE] + args
    if ranks > 1:
        cmd = [MPIEXEC, "--oversubscribe", "-n", str(ranks)] + cmd
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    return subprocess.Popen(cmd, cwd=cwd, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


@pytest.mark.parametrize("np_", [1, 2])
def test_sigusr1_checkpoints_and_restart_matches(tmp_path, np_):
    # The killed run is far too long to end by itself (5e6 steps, minutes); the first progress
    # line says the time loop is running. However late the signal lands (a loaded machine), the
    # restart and the straight run then go to the same step, a little past the checkpoint's.
    opts = ["-grid_n", "192,192", "-png_every", "0", "-progress_every", "2000"]
    p = start(opts + ["-steps", "5000000", "-output_dir", "killed"], tmp_path, np_)
    line = p.stdout.readline()
    while line and not line.startswith("step "):
        line = p.stdout.readline()
    assert line, "the run printed no progress line"
    p.send_signal(signal.SIGUSR1)  # mpiexec forwards SIGUSR1 to the ranks
    out, err = p.communicate(timeout=600)
    assert p.returncode == 3, f"exit {p.returncode}: {out[-1500:]} {err[-1500:]}"
    assert "stopped by SIGUSR1" in out
    cks = sorted((tmp_path / "killed").glob("checkpoint_*.vtkhdf"))
    assert len(cks) == 1 and not list((tmp_path / "killed").glob("*.tmp"))
    at = attrs(cks[0])
    assert at["complete"] == 1 and 0 < at["step"] < 5000000
    end = int(at["step"]) + 20000
    steps = ["-steps", str(end)]
    ok(run(opts + steps + ["-output_dir", "killed", "-restart", "latest"], tmp_path, np_,
           timeout=600))
    ok(run(opts + steps + ["-output_dir", "straight"], tmp_path, np_, timeout=600))
    a = fields(tmp_path / f"straight/checkpoint_{end:07d}.vtkhdf")
    b = fields(tmp_path / f"killed/checkpoint_{end:07d}.vtkhdf")
    for s in a:
        assert np.array_equal(a[s], b[s])


def test_max_walltime_exits_3_with_checkpoint(tmp_path):
    r = run(["-grid_n", "192,192", "-png_every", "0", "-steps", "100000000", "-max_walltime",
             "0.03", "-output_dir", "o"], tmp_path, 2)
    assert r.returncode == 3, r.stdout[-1000:] + r.stderr[-1000:]
    assert "stopped by the -max_walltime budget" in r.stdout
    (ck,) = (tmp_path / "o").glob("checkpoint_*.vtkhdf")
    assert attrs(ck)["complete"] == 1


def test_truncated_checkpoint_is_refused_previous_loads(tmp_path):
    opts = BASE + ["-checkpoint_every", "10", "-checkpoint_final", "false"]
    ok(run(opts + ["-steps", "20", "-output_dir", "o"], tmp_path))
    newest = tmp_path / "o/checkpoint_0000020.vtkhdf"
    data = newest.read_bytes()
    newest.write_bytes(data[: len(data) // 2])
    r = run(opts + ["-steps", "30", "-output_dir", "o", "-restart", str(newest)], tmp_path)
    assert r.returncode == 1
    line = error_line(r)
    assert str(newest) in line and "not a usable checkpoint" in line and "truncated" in line
    r = ok(run(opts + ["-steps", "30", "-output_dir", "o", "-restart", "latest"], tmp_path, 2))
    assert "skipping" in r.stderr and "checkpoint_0000020" in r.stderr
    assert "restart from o/checkpoint_0000010.vtkhdf: step 10" in r.stdout
    # a snapshot is not a checkpoint
    ok(run(BASE + ["-steps", "5", "-output_dir", "s"], tmp_path))
    r = run(BASE + ["-output_dir", "s2", "-restart", "s/morphogen_0000005.vtkhdf"], tmp_path)
    assert r.returncode == 1 and "no complete /morphogen restart record" in error_line(r)


def test_restart_from_older_checkpoint_keeps_series_unique(tmp_path):
    opts = BASE + ["-snapshot_every", "10", "-checkpoint_every", "10", "-checkpoint_keep", "5"]
    ok(run(opts + ["-steps", "30", "-output_dir", "o"], tmp_path))
    r = ok(run(opts + ["-steps", "40", "-output_dir", "o", "-restart",
                       "o/checkpoint_0000020.vtkhdf"], tmp_path, 2))
    assert "checkpoint_0000030.vtkhdf is newer than the restart point" in r.stdout
    series = json.loads((tmp_path / "o/morphogen.vtkhdf.series").read_text())
    names = [f["name"] for f in series["files"]]
    assert names == [f"morphogen_{s:07d}.vtkhdf" for s in (0, 10, 20, 30, 40)]
    assert [f["time"] for f in series["files"]] == [0.0, 5.0, 10.0, 15.0, 20.0]
    xmf = (tmp_path / "o/morphogen.xmf").read_text()
    assert xmf.count("<Time ") == 5
    assert (tmp_path / "o/checkpoint_0000030.vtkhdf.stale").exists()
    r = ok(run(opts + ["-steps", "40", "-output_dir", "o", "-restart", "latest"], tmp_path))
    assert "restart from o/checkpoint_0000040.vtkhdf" in r.stdout


def test_nan_guard_names_last_good_checkpoint(tmp_path):
    r = run(BASE + ["-dt", "4", "-force_dt", "-clamp", "false", "-steps", "2000",
                    "-checkpoint_every", "5", "-nan_check_every", "5", "-output_dir", "o"],
            tmp_path)
    assert r.returncode == 1
    line = error_line(r)
    assert "the run diverged" in line and "last good checkpoint: o/checkpoint_" in line
    good = line.split("last good checkpoint: ")[1].strip()
    for v in fields(tmp_path / good).values():
        assert np.isfinite(v).all()


def test_snapshot_precision_and_layout(tmp_path):
    ok(run(["-grid_n", "12,10,8", "-steps", "4", "-png_every", "0", "-snapshot_precision",
            "float64", "-output_dir", "o"], tmp_path, 2))
    with h5py.File(tmp_path / "o/morphogen_0000004.vtkhdf", "r") as f:
        assert "VTKHDF/CellData" not in f
        assert f["VTKHDF/PointData/a"].shape == (8, 10, 12)
        assert f["VTKHDF/PointData/a"].dtype == np.float64
        g = f["VTKHDF"]
        assert list(g.attrs["WholeExtent"]) == [0, 11, 0, 9, 0, 7]
        assert list(g.attrs["Origin"]) == [h / 2 for h in g.attrs["Spacing"]]  # the cell centres
    ok(run(["-grid_n", "12,10", "-steps", "4", "-png_every", "0", "-output_dir", "p"], tmp_path))
    with h5py.File(tmp_path / "p/morphogen_0000004.vtkhdf", "r") as f:
        assert f["VTKHDF/PointData/b"].shape == (1, 10, 12)
        assert f["VTKHDF/PointData/b"].dtype == np.float32
        g = f["VTKHDF"]
        assert list(g.attrs["WholeExtent"]) == [0, 11, 0, 9, 0, 0]
        h = g.attrs["Spacing"]
        assert list(g.attrs["Origin"]) == [h[0] / 2, h[1] / 2, 0]


def can_mount(path, opts):
    path.mkdir()
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", opts, "tmpfs", str(path)],
                       capture_output=True)
    return r.returncode == 0


def test_read_only_output_dir_fails_cleanly(tmp_path):
    ro = tmp_path / "ro"
    if os.geteuid() == 0:
        if not can_mount(ro, "ro,size=1m"):
            pytest.skip("running as root without permission to mount a read-only tmpfs")
    else:
        ro.mkdir()
        ro.chmod(0o555)
    try:
        r = run(BASE + ["-steps", "10", "-output_dir", str(ro)], tmp_path, 2)
        assert r.returncode == 4  # an output file could not be written
        assert "writing options" in error_line(r) and str(ro) in error_line(r)
        assert os.listdir(ro) == []
    finally:
        if os.geteuid() == 0:
            subprocess.run(["umount", str(ro)])


def test_full_disk_exits_4_and_keeps_previous_checkpoint(tmp_path):
    if os.geteuid() != 0:
        pytest.skip("needs root to mount a small tmpfs")
    full = tmp_path / "full"
    # one 128x128 float64 checkpoint (2 x 128 KiB) fits, a second one does not
    if not can_mount(full, "size=400k"):
        pytest.skip("no permission to mount a tmpfs")
    try:
        opts = ["-grid_n", "128,128", "-png_every", "0", "-checkpoint_every", "10"]
        r = run(opts + ["-steps", "30", "-output_dir", str(full)], tmp_path, 2)
        assert r.returncode == 4, r.stdout[-1000:] + r.stderr[-1000:]
        line = error_line(r)
        assert "writing checkpoint" in line and "checkpoint_0000020" in line
        assert "the last good checkpoint " + str(full) + "/checkpoint_0000010.vtkhdf is intact" \
            in line
        assert not list(full.glob("*.tmp"))
        r = ok(run(opts + ["-steps", "20", "-output_dir", "elsewhere", "-restart",
                           str(full / "checkpoint_0000010.vtkhdf")], tmp_path))
        assert "step 10" in r.stdout
    finally:
        subprocess.run(["umount", str(full)])


def test_time_and_walltime_triggers(tmp_path):
    # every T of simulated time: dt 0.5, T 5 -> steps 10, 20, 30; keep 10
    ok(run(BASE + ["-steps", "30", "-checkpoint_every_time", "5", "-checkpoint_keep", "10",
                   "-checkpoint_final", "false", "-snapshot_every_time", "7.5", "-output_dir",
                   "t"], tmp_path))
    steps = sorted(attrs(p)["step"] for p in (tmp_path / "t").glob("checkpoint_*.vtkhdf"))
    assert steps == [10, 20, 30]
    series = json.loads((tmp_path / "t/morphogen.vtkhdf.series").read_text())
    assert [f["time"] for f in series["files"]] == [0.0, 7.5, 15.0]
    # every W minutes of wall time (0.3 s) on a run of a few seconds; keep the newest 3
    r = ok(run(["-grid_n", "192,192", "-png_every", "0", "-steps", "150000",
                "-checkpoint_every_walltime", "0.005", "-checkpoint_keep", "3",
                "-checkpoint_final", "false", "-output_dir", "w"], tmp_path, 2))
    kept = list((tmp_path / "w").glob("checkpoint_*.vtkhdf"))
    assert len(kept) == 3, r.stdout[-500:]
    assert all(attrs(p)["complete"] == 1 for p in kept)


def test_mismatched_restart_is_refused_before_writing(tmp_path):
    ok(run(BASE + ["-steps", "20", "-output_dir", "o"], tmp_path))
    before = (tmp_path / "o/options_used.yaml").read_text()
    r = run(["-grid_n", "40,40", "-steps", "30", "-output_dir", "o", "-restart", "latest"],
            tmp_path)
    assert r.returncode == 1 and "does not match this run's -grid_n" in error_line(r)
    r = run(BASE + ["-model", "gray_scott", "-steps", "30", "-output_dir", "o", "-restart",
                    "latest"], tmp_path, 2)
    assert r.returncode == 1 and "written by model turing" in error_line(r)
    assert (tmp_path / "o/options_used.yaml").read_text() == before
    assert (tmp_path / "o/checkpoint_0000020.vtkhdf").exists()  # not retired


@pytest.mark.parametrize("grid,np_", [("48,40", 1), ("16,12,8", 2)])
def test_celldata_layout_checkpoint_restarts(tmp_path, grid, np_):
    """A checkpoint in the CellData layout (an image of the cell corners, as an intermediate
    development version wrote) restarts bitwise, on another rank count too; the .xmf then lists
    the CellData snapshots and the new PointData ones alike: cell data on the cell corners."""
    opts = ["-grid_n", grid, "-png_every", "0", "-progress_every", "100000", "-snapshot_every",
            "10"]
    ok(run(opts + ["-steps", "20", "-output_dir", "straight"], tmp_path, np_))
    ok(run(opts + ["-steps", "10", "-output_dir", "cells"], tmp_path, 3 - np_))
    for p in (tmp_path / "cells").glob("*.vtkhdf"):
        to_celldata_layout(p)
    n = [int(v) for v in grid.split(",")]
    with h5py.File(tmp_path / "cells/checkpoint_0000010.vtkhdf", "r") as f:
        assert f["VTKHDF/CellData/a"].shape == tuple([1] * (3 - len(n)) + n[::-1])
        assert "VTKHDF/PointData" not in f
        assert list(f["VTKHDF"].attrs["WholeExtent"])[1::2] == (n + [0])[:3]
    r = ok(run(opts + ["-steps", "20", "-output_dir", "cells", "-restart", "latest"], tmp_path,
               np_))
    assert "restart from cells/checkpoint_0000010.vtkhdf: step 10" in r.stdout
    a = fields(tmp_path / "straight/checkpoint_0000020.vtkhdf")
    b = fields(tmp_path / "cells/checkpoint_0000020.vtkhdf")
    assert sorted(a) == ["a", "b"]
    for s in a:
        assert np.array_equal(a[s], b[s]), f"{s}: max diff {np.abs(a[s] - b[s]).max()}"
    with h5py.File(tmp_path / "cells/checkpoint_0000020.vtkhdf", "r") as f:
        assert "VTKHDF/PointData" in f and "VTKHDF/CellData" not in f  # written as usual
    xmf = (tmp_path / "cells/morphogen.xmf").read_text()
    assert xmf.count('Center="Cell"') == 6 and 'Center="Node"' not in xmf, xmf
    assert "morphogen_0000010.vtkhdf:/VTKHDF/CellData/a" in xmf
    assert "morphogen_0000020.vtkhdf:/VTKHDF/PointData/a" in xmf
    mesh = " ".join(str(v) for v in reversed([v + 1 for v in n] + [1] * (3 - len(n))))
    assert xmf.count(f'Dimensions="{mesh}"') == 3, xmf  # one mesh for both layouts
    assert xmf.count(">0 0 0</DataItem>") == 3, xmf  # origin: the domain's corner
    # a mismatched grid in the CellData layout is still refused with the cell counts
    r = run(["-grid_n", "40,40", "-steps", "20", "-output_dir", "o2", "-restart",
             str(tmp_path / "cells/checkpoint_0000010.vtkhdf")], tmp_path)
    cells = (grid.split(",") + ["1"])[:3]
    assert r.returncode == 1 and f"grid {'x'.join(cells)} with spacing" in error_line(r)
