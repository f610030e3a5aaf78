#!/usr/bin/python3
"""Writes input/data/cavity_velocity_re125.h5, the steady lid-driven cavity flow that
input/cavity_gray_scott_replay.yaml reads with -velocity_file (the "velocity from another
code" workflow).

The flow is that of input/cavity_gray_scott.yaml (Stam stable fluids, 128 x 128 cells on a
1.25 x 1.25 square, lid speed 0.004, viscosity 4e-5: Re = 125), run by morphogen for --steps
steps (dt = 1) until it no longer changes, then stored as another code would: two float32
arrays /flow/u and /flow/v of shape (128, 128) (C order, x fastest), with the steps, the
relative change over the last --check steps and the generating command as attributes.

    /usr/bin/python3 postproc/make_cavity_velocity.py [--morphogen build/morphogen]
        [--steps 4000] [--check 500] [--ranks 2] [--out input/data/cavity_velocity_re125.h5]
"""
import argparse
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def run_flow(morphogen, steps, ranks, out_dir):
    cmd = ["mpiexec", "-n", str(ranks), morphogen, os.path.join(ROOT, "input", "cavity_gray_scott.yaml"),
           "-steps", str(steps), "-snapshot_every", "0", "-snapshot_precision", "float64",
           "-png_every", "0", "-summary", "false", "-output_dir", out_dir]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    subprocess.run(cmd, check=True, env=env, stdout=subprocess.DEVNULL)
    snaps = sorted(f for f in os.listdir(out_dir) if f.startswith("morphogen_") and
                   f.endswith(".vtkhdf"))
    with h5py.File(os.path.join(out_dir, snaps[-1]), "r") as f:
        pd = f["VTKHDF/PointData"]
        return pd["velocity_x"][()].reshape(128, 128), pd["velocity_y"][()].reshape(128, 128), cmd


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--morphogen", default=os.path.join(ROOT, "build", "morphogen"))
    ap.add_argument("--steps", type=int, default=4000)
    ap.add_argument("--check", type=int, default=500)
    ap.add_argument("--ranks", type=int, default=2)
    ap.add_argument("--out", default=os.path.join(ROOT, "input", "data", "cavity_velocity_re125.h5"))
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        u0, v0, _ = run_flow(a.morphogen, a.steps - a.check, a.ranks, os.path.join(tmp, "a"))
        u, v, cmd = run_flow(a.morphogen, a.steps, a.ranks, os.path.join(tmp, "b"))
    speed = np.hypot(u, v).max()
    change = max(np.abs(u - u0).max(), np.abs(v - v0).max()) / speed
    os.makedirs(os.path.dirname(a.out), exist_ok=True)
    with h5py.File(a.out, "w") as f:
        g = f.create_group("flow")
        g.create_dataset("u", data=u.astype(np.float32))
        g.create_dataset("v", data=v.astype(np.float32))
        g.attrs["steps"] = a.steps
        g.attrs["relative_change_over_last_steps"] = change
        g.attrs["last_steps"] = a.check
        g.attrs["command"] = " ".join(os.path.relpath(c, ROOT) if c.startswith(ROOT) else c
                                      for c in cmd)
    print(f"{a.out}: max speed {speed:.4g}, relative change over the last {a.check} steps "
          f"{change:.2e}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
