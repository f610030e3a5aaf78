"""morphogen-bench's own options: -help lists them all and times nothing; a mistyped or
out-of-range -bench_* option is one error line and a non-zero exit before any timing starts
(the bench otherwise runs for minutes before its first figure)."""
import os
import re

import pytest
from conftest import EXE, SOURCE, error_lines, run

BENCH = os.path.join(os.path.dirname(EXE), "morphogen-bench")
TIMING_LINE = re.compile(r"^(stream_triad|explicit_|output_|split_|scaling_|access_)", re.M)


def bench(args, cwd, ranks=1, timeout=120):
    return run(args, cwd, ranks, timeout, exe=BENCH)


def bench_sources_options():
    """Every -bench_* option name the bench's sources read (opt.integer("bench_...", ...))."""
    names = set()
    src = os.path.join(SOURCE, "src", "bench")
    for f in os.listdir(src):
        if f.endswith(".cpp"):
            text = open(os.path.join(src, f)).read()
            names.update(re.findall(r'opt\.\w+\(\s*"(bench_\w+)"', text))
    return names


@pytest.mark.parametrize("ranks", [1, 2])
def test_help_lists_every_option_and_times_nothing(tmp_path, ranks):
    p = bench(["-help"], tmp_path, ranks)
    assert p.returncode == 0, p.stderr
    listed = set(re.findall(r"^  -(bench_\w+) <", p.stdout, re.M))
    expected = bench_sources_options()
    assert len(expected) >= 20
    assert listed == expected
    assert "-bench_fuse_steps <4,8>:" in p.stdout
    assert not TIMING_LINE.search(p.stdout), p.stdout
    assert not os.listdir(tmp_path)


CASES = [
    ("misspelt", ["-bench_fuse_stepz", "3"], ["-bench_fuse_stepz", "did you mean -bench_fuse_steps"]),
    ("fuse_negative", ["-bench_fuse_steps", "4,-2"], ["-bench_fuse_steps -2", "allowed [0, 64]"]),
    ("fuse_too_deep", ["-bench_fuse_steps", "65"], ["-bench_fuse_steps 65", "allowed [0, 64]"]),
    ("fuse_not_int", ["-bench_fuse_steps", "4,x"], ["-bench_fuse_steps x", "not an integer"]),
    ("fuse_n_small", ["-bench_fuse_n", "4"], ["-bench_fuse_n 4", "allowed [8, 65536]"]),
    ("fuse_n_not_int", ["-bench_fuse_n", "2048,big"], ["-bench_fuse_n big", "not an integer"]),
    ("net_range", ["-bench_net_GBps", "0"], ["-bench_net_GBps", "allowed [1e-06, 1000000]"]),
    ("side_3d", ["-bench_3d_n", "4"], ["-bench_3d_n", "allowed [8, 1024]"]),
    ("access_rows", ["-bench_access_rows", "-1"], ["-bench_access_rows", "allowed [0, 1048576]"]),
    ("access_3d", ["-bench_access_3d_n", "2000"], ["-bench_access_3d_n", "allowed [0, 1024]"]),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_bad_option_fails_before_timing(tmp_path, case):
    _, args, needles = case
    p = bench(args, tmp_path, ranks=2, timeout=60)
    assert p.returncode != 0
    lines = error_lines(p)
    assert len(lines) == 1, p.stderr
    assert lines[0].startswith("morphogen-bench: error: ")
    for n in needles:
        assert n in lines[0], lines[0]
    assert not TIMING_LINE.search(p.stdout), p.stdout


def test_integrator_options_go_to_their_runs(tmp_path):
    """-explicit_vector_width, -explicit_fuse_steps and -ts_diffusion_solver (which morphogen
    refuses in runs of another integrator) apply to the bench's explicit and TS runs only: the
    split runs in the same section do not fail on them, and the TS run uses the solver given."""
    p = bench(["-bench_only_implicit", "true", "-bench_output_n", "0", "-bench_brusselator_T", "2",
               "-bench_steps_split", "1", "-explicit_vector_width", "256",
               "-explicit_fuse_steps", "2", "-ts_diffusion_solver", "ksp"], tmp_path, timeout=300)
    assert p.returncode == 0, p.stderr
    assert re.search(r"^split_vs_explicit grid=1024x1024 .*diffusion_solver=ksp", p.stdout, re.M)
    assert "TS diffusion solve: ksp (-ts_diffusion_solver ksp)" in p.stdout, p.stdout
    assert re.search(r"^brusselator_deck T=2\. ts ", p.stdout, re.M), p.stdout


def test_fused_section_keeps_its_depths(tmp_path):
    """A -explicit_fuse_steps given to the bench does not cap the fused section's own k."""
    p = bench(["-bench_only_fused", "true", "-bench_output_n", "0", "-bench_fuse_n", "64",
               "-bench_fuse_steps", "4", "-bench_fuse_steps_timed", "8",
               "-explicit_fuse_steps", "2"], tmp_path, timeout=120)
    assert p.returncode == 0, p.stderr
    assert re.search(r"^explicit_fused grid=64x64 stencil=9pt k=4 ", p.stdout, re.M), p.stdout
    # The kernel-alone rates and the bounds they give (bench/bench_kernel_rate.hpp).
    m = re.search(r"^explicit_row_kernel model=gray_scott stencil=9pt row=512 "
                  r"ns_per_cell_256bit=(\S+) ns_per_cell_512bit=(\S+) ", p.stdout, re.M)
    assert m and float(m.group(1)) > 0 and float(m.group(2)) > 0, p.stdout
    ceil = re.search(r"^explicit_ceiling stencil=9pt cell_updates_per_s=(\S+) ", p.stdout, re.M)
    serial = re.search(r"^explicit_serial_bound stencil=9pt cell_updates_per_s=(\S+) ", p.stdout, re.M)
    roof = re.search(r"^roofline_cell_updates_per_s=(\S+)", p.stdout, re.M)
    assert ceil and serial and roof, p.stdout
    c, s, r = float(ceil.group(1)), float(serial.group(1)), float(roof.group(1))
    assert abs(s - 1.0 / (1.0 / c + 1.0 / r)) <= 1e-3 * s, p.stdout
    # The fused wavefront over its ring alone, at the section's largest k.
    ring = re.search(r"^explicit_fused_ring stencil=9pt row=2048 levels=4 ns_per_cell=(\S+) "
                     r"cell_updates_per_s=(\S+) roofline_fraction=(\S+) ", p.stdout, re.M)
    ranks = re.search(r"^ranks=(\d+)", p.stdout, re.M)
    assert ring and ranks, p.stdout
    ns, cups, frac = (float(ring.group(i)) for i in (1, 2, 3))
    assert ns > 0 and abs(cups - int(ranks.group(1)) / (ns * 1e-9)) <= 1e-3 * cups, p.stdout
    assert abs(frac - cups / r) <= 1e-3 * frac, p.stdout


def sys_l3_mib():
    """The L3 size of cpu0 as Linux lists it (MiB), or None."""
    base = "/sys/devices/system/cpu/cpu0/cache"
    if not os.path.isdir(base):
        return None
    for d in sorted(os.listdir(base)):
        try:
            level = open(os.path.join(base, d, "level")).read().strip()
            size = open(os.path.join(base, d, "size")).read().strip()
        except OSError:
            continue
        if level == "3":
            scale = {"K": 1 / 1024, "M": 1, "G": 1024}.get(size[-1], 1 / 1048576)
            return float(size.rstrip("KMG")) * scale
    return None


@pytest.mark.parametrize("ranks", [1, 2])
def test_machine_line_and_state_against_l3(tmp_path, ranks):
    """The machine line (CPU, caches, ranks per node) and, on the k = 1 fused line, the grid's
    state per node against that L3."""
    p = bench(["-bench_only_fused", "true", "-bench_output_n", "0", "-bench_fuse_n", "64",
               "-bench_fuse_steps", "0", "-bench_fuse_steps_timed", "8", "-bench_stream_mb", "8",
               "-bench_access_rows", "0", "-bench_access_3d_n", "0"], tmp_path, ranks, 120)
    assert p.returncode == 0, p.stderr
    m = re.search(r'^machine cpu="([^"]*)" logical_cpus=(\d+) l1d_KiB=(\d+) l2_KiB=(\d+) '
                  r"l3_MiB=(\d+) avx512=(yes|no) nodes=1 ranks_per_node=(\d+)$", p.stdout, re.M)
    assert m, p.stdout
    assert int(m.group(2)) == os.sysconf("SC_NPROCESSORS_ONLN") and int(m.group(7)) == ranks
    l3 = sys_l3_mib()
    if l3 is not None:
        assert int(m.group(5)) == round(l3)
    flags = open("/proc/cpuinfo").read()
    assert (m.group(6) == "yes") == (" avx512f" in flags)
    f = re.search(r"^explicit_fused grid=64x64 stencil=9pt k=1 .* state_MiB_per_node=(\S+) "
                  r"in_l3=(yes|no|unknown)$", p.stdout, re.M)
    assert f, p.stdout
    assert float(f.group(1)) == pytest.approx(16 * 64 * 64 / 2**20, rel=1e-3)
    assert f.group(2) == ("unknown" if not l3 else "yes")
