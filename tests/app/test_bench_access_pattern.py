"""morphogen-bench's access-pattern section (-bench_only_access_pattern): each memory pattern of
an explicit step is printed once with a positive rate, its ns per cell consistent with the rate,
the in-place ring sweeps checked equal to the out-of-place sweeps, and no other section runs."""
import os
import re

import pytest
from conftest import EXE, run

BENCH = os.path.join(os.path.dirname(EXE), "morphogen-bench")
NAMES = ["in_place_pointwise", "in_place_save_old", "ring_pointwise", "ring_pointwise_stream",
         "ring_xtaps", "ring_5pt", "ring_5pt_prefetch", "ring_5pt_stream",
         "ring_5pt_prefetch_stream", "out_of_place_5pt"]
NAMES_3D = ["3d_ring_7pt_blocked", "3d_ring_7pt_blocked_prefetch", "3d_ring_7pt_unblocked",
            "3d_out_of_place_7pt", "3d_ring_9row_blocked_prefetch"]
LINE = re.compile(r"^access_pattern name=(\w+) "
                  r"(?:rows_per_rank=(\d+)x4096|cells_per_rank=(\d+)x(\d+)x(\d+)) "
                  r"ns_per_cell_per_rank=([\d.]+) cell_updates_per_s=([\d.e+-]+) "
                  r"fraction=([\d.]+)$", re.M)


@pytest.mark.parametrize("ranks", [1, 2])
def test_access_pattern_section(tmp_path, ranks):
    rows, side = 12, 16
    p = run(["-bench_only_access_pattern", "true", "-bench_access_rows", str(rows),
             "-bench_access_3d_n", str(side), "-bench_stream_mb", "8"], tmp_path, ranks, 120,
            exe=BENCH)
    assert p.returncode == 0, p.stderr
    found = LINE.findall(p.stdout)
    assert [f[0] for f in found] == NAMES + NAMES_3D, p.stdout
    roof = float(re.search(r"^roofline_cell_updates_per_s=([\d.e+-]+)$", p.stdout, re.M).group(1))
    for name, r, nx, ny, nz, ns, cups, frac in found:
        if name in NAMES:
            assert int(r) == rows
        else:  # side^2 x side / ranks (at least 4 planes) per rank
            assert (int(nx), int(ny), int(nz)) == (side, side, max(4, side // ranks))
        ns, cups, frac = float(ns), float(cups), float(frac)
        assert ns > 0 and cups > 0
        # rate = ranks / (ns per cell and rank) (3 printed digits)
        assert cups == pytest.approx(ranks / (ns * 1e-9), rel=2e-3 + 1e-3 / ns), name
        assert frac == pytest.approx(cups / roof, rel=2e-3, abs=1e-3), name
    assert "access_pattern check ring_5pt_equals_out_of_place=yes" in p.stdout
    assert "access_pattern check 3d_ring_blocked_equals_out_of_place=yes" in p.stdout
    # x86-64 always has streaming stores (SSE2 at least): the *_stream lines measure them
    assert re.search(r"^access_pattern streaming_stores=(512|256|128)-bit$", p.stdout, re.M)
    assert not re.search(r"^(explicit_|output_|split_|scaling_)", p.stdout, re.M), p.stdout
