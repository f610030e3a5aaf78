"""-flush_subnormals (core/float_env.hpp): a Gray-Scott run whose activator dies out (64², F = 0.03,
k = 0.07) drives it into the subnormal range (|x| < 2.2e-308) with IEEE arithmetic
(-flush_subnormals false: every cell subnormal after 10,000 steps); with the default (true) no
value is subnormal, the dying species differs by less than 1e-300 and the other is bitwise the
same."""
import glob
import os

import h5py
import numpy as np

from conftest import SOURCE, run

DECK = os.path.join(SOURCE, "input", "gray_scott_pearson_spots.yaml")
GRID = ["-grid_n", "64,64", "-grid_L", "0.625", "-steps", "10000"]
TINY = np.finfo(np.float64).tiny  # 2.2e-308


def final_state(out):
    snap = sorted(glob.glob(os.path.join(out, "morphogen_*.vtkhdf")))[-1]
    with h5py.File(snap, "r") as f:
        g = f["VTKHDF/PointData"]
        return {k: g[k][()] for k in g}


def test_flush_changes_only_the_subnormal_range(tmp_path):
    states = {}
    for flag in ("default", "false"):
        out = tmp_path / flag
        extra = [] if flag == "default" else ["-flush_subnormals", "false"]
        p = run([DECK] + GRID + ["-params_F", "0.03", "-params_k", "0.07", "-snapshot_precision", "float64",
                 "-png_every", "0", "-summary", "false", "-output_dir", str(out)] + extra,
                tmp_path, ranks=2)
        assert p.returncode == 0, p.stderr
        states[flag] = final_state(out)
    ieee, flushed = states["false"]["a"], states["default"]["a"]
    subnormal = lambda x: np.count_nonzero((x != 0) & (np.abs(x) < TINY))
    assert subnormal(ieee) == ieee.size  # the case reaches the range
    assert subnormal(flushed) == 0
    assert np.max(np.abs(flushed - ieee)) < 1e-300
    assert states["default"]["b"].tobytes() == states["false"]["b"].tobytes()


def test_bad_value_is_one_line(tmp_path):
    p = run([DECK, "-steps", "1", "-flush_subnormals", "maybe", "-output_dir",
             str(tmp_path / "o")], tmp_path)
    assert p.returncode != 0
    assert "-flush_subnormals maybe" in p.stderr and "true or false" in p.stderr, p.stderr
