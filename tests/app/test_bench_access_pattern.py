"""morphogen-bench's access-pattern section (-bench_only_access_pattern): each memory pattern of
an explicit step is printed once with a positive rate, its ns per cell consistent with the rate,
the in-place ring sweep checked equal to the out-of-place sweep, and no other section runs."""
import os
import re

import pytest
from conftest import EXE, run

BENCH = os.path.join(os.path.dirname(EXE), "morphogen-bench")
NAMES = ["in_place_pointwise", "in_place_save_old", "ring_pointwise", "ring_xtaps", "ring_5pt",
         "ring_5pt_prefetch", "out_of_place_5pt"]
LINE = re.compile(r"^access_pattern name=(\w+) rows_per_rank=(\d+)x4096 ns_per_cell_per_rank=([\d.]+) "
                  r"cell_updates_per_s=([\d.e+-]+) fraction=([\d.]+)$", re.M)


@pytest.mark.parametrize("ranks", [1, 2])
def test_access_pattern_section(tmp_path, ranks):
    rows = 12
    p = run(["-bench_only_access_pattern", "true", "-bench_access_rows", str(rows),
             "-bench_stream_mb", "8"], tmp_path, ranks, 120, exe=BENCH)
    assert p.returncode == 0, p.stderr
    found = LINE.findall(p.stdout)
    assert [f[0] for f in found] == NAMES, p.stdout
    roof = float(re.search(r"^roofline_cell_updates_per_s=([\d.e+-]+)$", p.stdout, re.M).group(1))
    for name, r, ns, cups, frac in found:
        assert int(r) == rows
        ns, cups, frac = float(ns), float(cups), float(frac)
        assert ns > 0 and cups > 0
        # cells = (rows - 2) * 4096 per rank: rate = ranks / (ns per cell) (3 printed digits)
        assert cups == pytest.approx(ranks / (ns * 1e-9), rel=2e-3 + 1e-3 / ns), name
        assert frac == pytest.approx(cups / roof, rel=2e-3, abs=1e-3), name
    assert "access_pattern check ring_5pt_equals_out_of_place=yes" in p.stdout
    assert not re.search(r"^(explicit_|output_|split_|scaling_)", p.stdout, re.M), p.stdout
