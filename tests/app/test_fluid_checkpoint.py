"""The stable-fluids state in checkpoints and the velocity in snapshots (-fluid), end to end:
- restart equivalence: N steps straight == N/2, checkpoint, restart from `latest` to N, on 1 and
  2 ranks (same rank count), for an advected cavity (explicit scheme) and a channel past an
  obstacle without -advect (split scheme): the species, velocity_x, velocity_y and
  fluid_pressure of the final checkpoints are bitwise equal. Bitwise is possible because the
  checkpoint holds everything the fluid step reads: the velocity and the last pressure, which
  is the initial guess of the next pressure solve where it is iterative (CG + GAMG: always
  with an obstacle; with a zero guess instead the restarted flow differs in the last digits,
  1e-14 .. 4e-12 measured: a restart from p = 0 would fail this test);
- written on 2 ranks and restarted on 1: equal to 1e-8 of each field's size (the pressure
  solve's rtol: its GAMG preconditioner differs by rank count; measured 5e-12);
- a -fluid run refuses a checkpoint without fluid state, and a run without -fluid refuses one
  with it: one line naming the file and -fluid, exit 1, the output directory untouched;
- snapshots of a -fluid run without -advect carry velocity_x, velocity_y (not the pressure),
  equal to the checkpoint's velocity; the .xmf index lists them beside the species.
Fields are compared with h5py."""
import os
import re

import h5py
import numpy as np
import pytest

from conftest import run

CAVITY = ["-grid_n", "40,32", "-grid_L", "40,32", "-grid_bc", "neumann", "-dt", "0.5",
          "-advect", "a,b", "-fluid", "cavity", "-fluid_viscosity", "0.5",
          "-fluid_lid_speed", "1", "-png_every", "0", "-progress_every", "100000"]
CHANNEL = ["-grid_n", "40,32", "-grid_L", "40,32", "-grid_bc", "neumann", "-integrator", "split",
           "-dt", "1", "-fluid", "channel", "-fluid_viscosity", "0.2", "-fluid_inflow", "0.8",
           "-fluid_obstacle", "(x-12)^2 + (y-16)^2 < 25", "-png_every", "0",
           "-progress_every", "100000"]
CASES = {"cavity_advected": CAVITY, "channel_obstacle": CHANNEL}
FLUID = ["velocity_x", "velocity_y", "fluid_pressure"]


def fields(path):
    with h5py.File(path, "r") as f:
        g = f["VTKHDF/PointData"]
        return {k: g[k][...] for k in g}


def attrs(path):
    with h5py.File(path, "r") as f:
        return {k: (v.decode() if isinstance(v, bytes) else v) for k, v in f["morphogen"].attrs.items()}


def ok(r):
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    return r


def refused(r):
    assert r.returncode == 1, r.stdout[-2000:] + r.stderr[-2000:]
    lines = [l for l in r.stderr.splitlines() if l.startswith("morphogen:")]
    assert len(lines) >= 1, r.stderr
    return lines[0]


@pytest.mark.parametrize("np_", [1, 2])
@pytest.mark.parametrize("case", CASES)
def test_fluid_restart_is_bitwise(tmp_path, case, np_):
    opts = CASES[case]
    ok(run(opts + ["-steps", "16", "-output_dir", "straight"], tmp_path, np_))
    ok(run(opts + ["-steps", "8", "-output_dir", "halves"], tmp_path, np_))
    r = ok(run(opts + ["-steps", "16", "-output_dir", "halves", "-restart", "latest"], tmp_path,
               np_))
    assert "restart from halves/checkpoint_0000008.vtkhdf: step 8" in r.stdout
    a = fields(tmp_path / "straight/checkpoint_0000016.vtkhdf")
    b = fields(tmp_path / "halves/checkpoint_0000016.vtkhdf")
    assert sorted(a) == sorted(["a", "b"] + FLUID)
    # The flow is not trivial (a test of a flow at rest could not fail).
    assert np.abs(a["velocity_x"]).max() > 0.05 and np.abs(a["velocity_y"]).max() > 0.01
    assert np.abs(a["fluid_pressure"]).max() > 0
    for s in a:
        assert np.array_equal(a[s], b[s]), f"{s}: max diff {np.abs(a[s] - b[s]).max()}"
    assert attrs(tmp_path / "halves/checkpoint_0000016.vtkhdf")["fluid"] == CASES[case][
        CASES[case].index("-fluid") + 1]


def test_fluid_restart_on_other_rank_count(tmp_path):
    opts = CAVITY
    ok(run(opts + ["-steps", "16", "-output_dir", "straight"], tmp_path, 1))
    ok(run(opts + ["-steps", "8", "-output_dir", "halves"], tmp_path, 2))
    ok(run(opts + ["-steps", "16", "-output_dir", "halves", "-restart", "latest"], tmp_path, 1))
    a = fields(tmp_path / "straight/checkpoint_0000016.vtkhdf")
    b = fields(tmp_path / "halves/checkpoint_0000016.vtkhdf")
    for s in a:
        scale = max(np.abs(a[s]).max(), 1e-30)
        assert np.abs(a[s] - b[s]).max() <= 1e-8 * scale, \
            f"{s}: max diff {np.abs(a[s] - b[s]).max()} (scale {scale})"


def test_restart_without_fluid_state_is_refused(tmp_path):
    plain = [o for o in CAVITY]
    for k in ("-advect", "-fluid", "-fluid_viscosity", "-fluid_lid_speed"):
        i = plain.index(k)
        del plain[i:i + 2]
    ok(run(plain + ["-steps", "4", "-output_dir", "plain"], tmp_path))
    ok(run(CAVITY + ["-steps", "4", "-output_dir", "flow"], tmp_path))
    for d in ("plain", "flow"):
        before = {p: os.path.getmtime(tmp_path / d / p) for p in os.listdir(tmp_path / d)}
        other = CAVITY if d == "plain" else plain
        line = refused(run(other + ["-steps", "8", "-output_dir", d, "-restart", "latest"],
                           tmp_path))
        assert f"-restart {d}/checkpoint_0000004.vtkhdf" in line, line
        if d == "plain":
            assert "no fluid state" in line and "-fluid cavity" in line, line
        else:
            assert "holds the flow of -fluid cavity" in line and "this run has no -fluid" in line
        after = {p: os.path.getmtime(tmp_path / d / p) for p in os.listdir(tmp_path / d)}
        assert before == after, f"{d}: the output changed"


def test_snapshots_carry_the_fluid_velocity_without_advect(tmp_path):
    ok(run(CHANNEL + ["-steps", "6", "-snapshot_every", "3", "-output_dir", "out"], tmp_path, 2))
    snap = fields(tmp_path / "out/morphogen_0000006.vtkhdf")
    assert sorted(snap) == ["a", "b", "velocity_x", "velocity_y"]
    ck = fields(tmp_path / "out/checkpoint_0000006.vtkhdf")
    for d in ("velocity_x", "velocity_y"):  # float32 snapshot of the float64 state
        assert snap[d].dtype == np.float32
        assert np.allclose(snap[d], ck[d], rtol=1e-6, atol=1e-7 * np.abs(ck[d]).max())
    assert np.abs(ck["velocity_x"]).max() > 0.5  # the inflow
    xmf = (tmp_path / "out/morphogen.xmf").read_text()
    for name in ("a", "b", "velocity_x", "velocity_y"):
        assert re.search(rf'<Attribute Name="{name}"', xmf), name
    assert "fluid_pressure" not in xmf
