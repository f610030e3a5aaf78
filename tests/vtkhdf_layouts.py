"""Test helper: rewrite a morphogen VTKHDF file (PointData at the cell centres, WholeExtent
0..n-1, Origin h/2) in the CellData layout an intermediate development version wrote (CellData
of an image of the cell corners: WholeExtent 0..n, z 0..0 in 2-D, Origin 0), to check that
such files are still read."""
import h5py
import numpy as np


def to_celldata_layout(path):
    with h5py.File(path, "r+") as f:
        g = f["VTKHDF"]
        ext = [int(v) for v in g.attrs["WholeExtent"]]
        g.move("PointData", "CellData")
        g.attrs["WholeExtent"] = np.array([ext[2 * a + 1] + 1 if i and ext[2 * a + 1] > 0 else 0
                                           for a in range(3) for i in (0, 1)], dtype=np.int32)
        g.attrs["Origin"] = np.zeros(3)
    return path
