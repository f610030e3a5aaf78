#!/usr/bin/python3
"""morphogen beside Ready (https://github.com/GollyGang/ready) on the same machine, in one run.

    /usr/bin/python3 postproc/vs_ready.py --rdy PATH/TO/rdy [--ranks 2]
        [--cases 2d:1024,2d:2048,3d:128] [--updates 1e9] [--repeat 3]
        [--opencl-platform P] [--opencl-device D] [--morphogen build/morphogen]
        [--mpiexec mpiexec] [--workdir DIR] [--json FILE]

Both codes run the same explicit Gray-Scott equations in double precision on a periodic grid of
unit spacing: Ready's formula rule (its own example's kinetics: D 0.082 and 0.041, F 0.035,
K 0.064, timestep 1) with its default "medium" Laplacian, the 9-point Mehrstellen stencil in
2-D and the 27-point stencil in 3-D; morphogen's gray_scott model (the same equations, species
roles swapped) with -stencil 9pt or 27pt on `--ranks` MPI ranks. Both start from the substrate
at 1 with the autocatalyst in the central 20 % of each axis (Ready: white noise there, its own
example's seed; morphogen: 0.5). N must be a multiple of 4 (Ready updates blocks of 4 cells).
Ready runs on OpenCL platform/device `--opencl-platform`/`--opencl-device` (its default 0/0;
printed with the results: a GPU there is not a like-for-like comparison with CPU ranks). Ready's command-line utility
runs `rdy -i CASE.vti -n N` (N iterations, no output file); morphogen runs `-steps N`.
Each code is timed at two step counts N1 and N2 = N1 + N (N of about `--updates` cell-updates,
best of `--repeat` runs each), so start-up, OpenCL compilation, set-up and final output cancel:
rate = cells (N2 - N1) / (t(N2) - t(N1)). Prints one line per case with both rates in
Mcell-updates/s, their ratio and the target (morphogen >= 1.3 x Ready); --json writes them.
Ready is not a dependency of morphogen: this script only needs its `rdy` binary by path
(tools/build_ready.sh builds one from a Ready checkout on Debian 12).
Exit codes: 0 done, 2 bad arguments or a run that failed (one line naming it).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
TARGET = 1.3

READY_RULE = """<?xml version="1.0"?>
<VTKFile type="ImageData" version="0.1" byte_order="LittleEndian">
  <RD format_version="6">
    <description>Gray-Scott in double precision (morphogen's postproc/vs_ready.py)</description>
    <rule name="Gray-Scott" type="formula" wrap="1">
      <param name="timestep">1</param>
      <param name="D_a">0.082</param>
      <param name="D_b">0.041</param>
      <param name="K">0.064</param>
      <param name="F">0.035</param>
      <formula number_of_chemicals="2" accuracy="medium">
        delta_a = D_a * laplacian_a - a*b*b + F*(1.0-a);
        delta_b = D_b * laplacian_b + a*b*b - (F+K)*b;
      </formula>
    </rule>
    <initial_pattern_generator apply_when_loading="true">
      <overlay chemical="a"><overwrite /><constant value="1" /><everywhere /></overlay>
      <overlay chemical="b"><overwrite /><white_noise low="0" high="1" />
        <rectangle><point3D x="0.4" y="0.4" z="0.4" /><point3D x="0.6" y="0.6" z="0.6" />
        </rectangle>
      </overlay>
      <overlay chemical="a"><subtract /><other_chemical chemical="b" />
        <rectangle><point3D x="0.4" y="0.4" z="0.4" /><point3D x="0.6" y="0.6" z="0.6" />
        </rectangle>
      </overlay>
    </initial_pattern_generator>
  </RD>
  <ImageData WholeExtent="{extent}" Origin="0 0 0" Spacing="1 1 1">
  <Piece Extent="{extent}">
    <PointData>
{arrays}    </PointData>
    <CellData>
    </CellData>
  </Piece>
  </ImageData>
</VTKFile>
"""


class Failure(Exception):
    """A run or argument that stops the comparison: one line for the user."""


def parse_case(text):
    """'2d:1024' or '3d:128' -> (dim, n)."""
    try:
        dim, n = text.split(":")
        dim, n = {"2d": 2, "3d": 3}[dim.lower()], int(n)
    except (ValueError, KeyError):
        raise Failure(f"--cases {text}: expected 2d:N or 3d:N (N cells per axis)")
    if n < 8 or n % 4:
        raise Failure(f"--cases {text}: N must be a multiple of 4, at least 8 (Ready's blocks)")
    return dim, n


def write_ready_file(path, dim, n):
    """Ready's input for the case: the rule above on an n^dim image (the initial pattern is made
    by Ready on loading; the stored zeros only set the size and the double type)."""
    cells = n**dim
    extent = f"0 {n - 1} 0 {n - 1} 0 {n - 1 if dim == 3 else 0}"
    zeros = ("0 " * cells).rstrip()
    arrays = "".join(
        f'      <DataArray type="Float64" Name="{c}" format="ascii">\n{zeros}\n      </DataArray>\n'
        for c in "ab")
    with open(path, "w") as f:
        f.write(READY_RULE.format(extent=extent, arrays=arrays))


def morphogen_command(args, dim, n, steps, out_dir):
    """morphogen's run of the case (gray_scott: a the autocatalyst = Ready's b)."""
    grid = ",".join([str(n)] * dim)
    square = "square(Lx/2, Ly/2, Lx/10)" + ("*(abs(z - Lz/2) <= Lz/10)" if dim == 3 else "")
    cmd = [args.morphogen, "-model", "gray_scott", "-grid_n", grid, "-grid_L", grid,
           "-stencil", "9pt" if dim == 2 else "27pt", "-D_a", "0.041", "-D_b", "0.082",
           "-params_F", "0.035", "-params_k", "0.064", "-dt", "1", "-steps", str(steps),
           "-init_a", f"0.5*{square}", "-init_b", f"1 - 0.5*{square}", "-summary", "false",
           "-checkpoint_final", "false", "-progress_every", str(steps), "-output_dir", out_dir]
    return [args.mpiexec, "-n", str(args.ranks)] + cmd if args.ranks > 1 else cmd


def timed(cmd, what, cwd):
    """Wall seconds of one run; Failure with the run's last line when it fails."""
    t0 = time.perf_counter()
    try:
        r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
    except OSError as e:
        raise Failure(f"{what}: cannot run {cmd[0]} ({e.strerror})")
    seconds = time.perf_counter() - t0
    if r.returncode != 0:
        raise Failure(f"{what} exited with code {r.returncode}: {reason(r.stdout, r.stderr)}")
    return seconds


def reason(stdout, stderr):
    """The line that says why a run failed: the first naming an error (morphogen writes
    "morphogen: error: ..." to stderr, rdy its errors to stdout), else the last line."""
    lines = [l.strip() for l in (stderr + "\n" + stdout).splitlines() if l.strip()]
    for l in lines:
        if "error" in l.lower() and not l.startswith("--"):
            return l
    return lines[-1] if lines else "no output"


def rate(make_cmd, cells, n1, n2, repeat, what, cwd):
    """Cell-updates per second from the best times at n1 and n2 steps."""
    best = {}
    for steps in (n1, n2):
        best[steps] = min(timed(make_cmd(steps), f"{what} ({steps} steps)", cwd)
                          for _ in range(repeat))
    dt = best[n2] - best[n1]
    if dt <= 0:
        raise Failure(f"{what}: {n2} steps took no longer than {n1}; raise --updates")
    return cells * (n2 - n1) / dt


def compare_case(args, dim, n, work):
    cells = n**dim
    steps = max(10, round(args.updates / cells))
    n1, n2 = max(2, steps // 10), max(2, steps // 10) + steps
    vti = os.path.join(work, f"ready_{dim}d_{n}.vti")
    write_ready_file(vti, dim, n)
    ready_cmd = [args.rdy, "-i", vti]
    if args.opencl_platform is not None:
        ready_cmd += ["-l", str(args.opencl_platform)]
    if args.opencl_device is not None:
        ready_cmd += ["-g", str(args.opencl_device)]
    out_dir = os.path.join(work, f"morphogen_{dim}d_{n}")
    r_ready = rate(lambda s: ready_cmd + ["-n", str(s)], cells, n1, n2, args.repeat, "rdy", work)
    r_morph = rate(lambda s: morphogen_command(args, dim, n, s, out_dir), cells, n1, n2,
                   args.repeat, "morphogen", work)
    return {"case": f"{dim}d:{n}", "stencil": "9pt" if dim == 2 else "27pt", "cells": cells,
            "steps": [n1, n2], "ranks": args.ranks, "morphogen": r_morph, "ready": r_ready,
            "ratio": r_morph / r_ready, "target": TARGET,
            "opencl": [args.opencl_platform or 0, args.opencl_device or 0]}


def parse_args(argv):
    p = argparse.ArgumentParser(description="morphogen beside Ready's rdy, same problem.")
    p.add_argument("--rdy", required=True, help="path of Ready's command-line utility rdy")
    p.add_argument("--ranks", type=int, default=2, help="morphogen's MPI ranks (default 2)")
    p.add_argument("--cases", default="2d:1024,2d:2048,3d:128")
    p.add_argument("--updates", type=float, default=1e9, help="cell-updates per timed pair")
    p.add_argument("--repeat", type=int, default=3, help="runs per step count (best kept)")
    p.add_argument("--opencl-platform", type=int, help="Ready's -l")
    p.add_argument("--opencl-device", type=int, help="Ready's -g")
    p.add_argument("--morphogen", default=os.path.join(HERE, "..", "build", "morphogen"))
    p.add_argument("--mpiexec", default="mpiexec")
    p.add_argument("--workdir", help="where the inputs and outputs go (default: a temp dir)")
    p.add_argument("--json", help="also write the results here")
    args = p.parse_args(argv)
    if not (os.path.isfile(args.rdy) and os.access(args.rdy, os.X_OK)):
        raise Failure(f"--rdy {args.rdy}: not an executable file")
    if args.ranks < 1 or args.repeat < 1 or not args.updates > 0:
        raise Failure("--ranks, --repeat and --updates must be positive")
    args.case_list = [parse_case(c) for c in args.cases.split(",") if c]
    return args


def main(argv):
    try:
        args = parse_args(argv)
        with tempfile.TemporaryDirectory() as tmp:
            work = os.path.abspath(args.workdir or tmp)
            os.makedirs(work, exist_ok=True)
            print(f"morphogen on {args.ranks} rank(s); Ready on OpenCL platform "
                  f"{args.opencl_platform or 0}, device {args.opencl_device or 0}; Mcell-updates/s")
            print(f"{'case':10} {'stencil':7} {'morphogen':>12} {'Ready':>12} {'ratio':>6}  target",
                  flush=True)
            results = []
            for dim, n in args.case_list:
                r = compare_case(args, dim, n, work)
                results.append(r)
                met = "met" if r["ratio"] >= TARGET else "not met"
                print(f"{r['case']:10} {r['stencil']:7} {r['morphogen'] / 1e6:12.1f} "
                      f"{r['ready'] / 1e6:12.1f} {r['ratio']:6.2f}  >= {TARGET} ({met})",
                      flush=True)
        if args.json:
            with open(args.json, "w") as f:
                json.dump({"unit": "cell-updates/s", "results": results}, f, indent=1)
    except Failure as e:
        print(f"vs_ready: error: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
