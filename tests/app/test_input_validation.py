"""Input validation, help and messages (issue 10): decks checked by a YAML parser
(file:line:column), values of any length, one-expression values, spots() limits, restart
attributes, -h/--help/-help/-help petsc/--version, -options_file problems, hints for options of
other models, sweeps without a sweep: section, and numbers printed for people. Every bad input:
exit non-zero, exactly one error line naming the option or deck key, existing output
untouched."""
import os
import re

import h5py
import numpy as np
import pytest

from conftest import SOURCE, run

SMALL = ["-grid_n", "16,16", "-steps", "2", "-png_every", "0", "-progress_every", "1000"]


def error_lines(proc):
    lines = []
    for l in proc.stderr.splitlines():
        if l.startswith("-----"):
            break
        if l.strip():
            lines.append(l)
    return lines


def one_error(proc, *needles):
    assert proc.returncode != 0, proc.stdout[-2000:]
    lines = error_lines(proc)
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("morphogen: error: "), lines[0]
    for n in needles:
        assert n in lines[0], lines[0]
    return lines[0]


def snapshot(d):
    """Every file under d with its bytes."""
    out = {}
    for root, _, files in os.walk(d):
        for f in files:
            p = os.path.join(root, f)
            with open(p, "rb") as fh:
                out[os.path.relpath(p, d)] = fh.read()
    return out


@pytest.fixture
def previous_run(tmp_path):
    """An output directory holding a finished run (a checkpoint, options_used.yaml)."""
    out = tmp_path / "out"
    r = run(SMALL + ["-output_dir", str(out)], cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    return out


# --- decks --------------------------------------------------------------------------------

DECKS = [
    ("syntax", "model: turing\ngrid: [unclosed\n", [r"bad\.yaml:3:1: "]),
    ("duplicate", "steps: 10\nsteps: 20\n", [r"bad\.yaml:2:1: duplicate key steps"]),
    ("duplicate_flattened", "grid:\n  n: 16,16\ngrid_n: 8,8\n",
     [r"bad\.yaml:3:1: duplicate key grid_n \(option -grid_n, already given at line 2\)"]),
    ("second_document", "steps: 1\n---\nsteps: 2\n", [r"bad\.yaml:\d+:\d+: a second YAML document"]),
    ("nul", "steps: 1\nmo\0del: turing\n", [r"bad\.yaml:2:3: NUL byte"]),
    ("duplicate_ignoring_case", "D: {a: 0.0625}\nd: {a: 5}\n",
     [r"bad\.yaml:2:5: duplicate key a \(option -d_a, already given at line 1\)"]),
    ("log_view", "log_view: \":/nonexistent/x.txt\"\n",
     [r"-log_view :/nonexistent/x.txt \(in the deck or an options file\): PETSc reads its "
      r"logging options from the command line only"]),
    ("empty", "", [r"bad\.yaml:1:1: empty deck"]),
    ("comments_only", "# nothing\n   # here\n\n", [r"bad\.yaml:1:1: empty deck"]),
]


@pytest.mark.parametrize("case", DECKS, ids=[c[0] for c in DECKS])
def test_bad_deck(case, previous_run, tmp_path):
    _, text, patterns = case
    deck = tmp_path / "bad.yaml"
    deck.write_bytes(text.encode())
    before = snapshot(previous_run)
    line = one_error(run([str(deck), "-output_dir", str(previous_run)], cwd=tmp_path))
    for p in patterns:
        assert re.search(p, line), line
    assert snapshot(previous_run) == before


@pytest.mark.parametrize("ranks", [1, 2])
def test_bad_options_file(ranks, previous_run, tmp_path):
    before = snapshot(previous_run)
    one_error(run(["-options_file", "nope.txt", "-output_dir", str(previous_run)], cwd=tmp_path,
                  ranks=ranks), "-options_file nope.txt: no such file")
    (tmp_path / "plain.txt").write_text("-steps 2\nsteps 3\n")
    one_error(run(["-options_file", "plain.txt", "-output_dir", str(previous_run)], cwd=tmp_path,
                  ranks=ranks), "-options_file plain.txt:2: expected -option")
    (tmp_path / "o.yaml").write_text("steps: 2\nsteps: 3\n")
    one_error(run(["-options_file", "o.yaml", "-output_dir", str(previous_run)], cwd=tmp_path,
                  ranks=ranks), "o.yaml:2:1: duplicate key steps")
    one_error(run(["-options_file"], cwd=tmp_path, ranks=ranks), "-options_file: needs a file name")
    assert snapshot(previous_run) == before


NESTED = [  # (files, the options file given, the error's text)
    ({"self.txt": "-options_file self.txt\n"}, "self.txt",
     "-options_file self.txt:1: -options_file self.txt: includes a file that is already being "
     "read (a cycle)"),
    ({"m1.txt": "-options_file m2.txt\n", "m2.txt": "-steps 2\n-options_file m1.txt\n"},
     "m1.txt", "m2.txt:2: -options_file m1.txt: includes a file"),
    ({"dup.yaml": "model: turing\nmodel: gray_scott\n", "y.txt": "-options_file_yaml dup.yaml\n"},
     "y.txt", "-options_file_yaml dup.yaml:2:1: duplicate key model"),
    ({"bin.yaml": "a\0b", "b.txt": "-options_file bin.yaml\n"}, "b.txt", "bin.yaml:1:2: NUL byte"),
    ({"lv.txt": "-log_view :x.txt:ascii_bogus\n"}, "lv.txt",
     "-log_view :x.txt:ascii_bogus (in the deck or an options file)"),
]


@pytest.mark.parametrize("ranks", [1, 2])
def test_nested_options_files(ranks, previous_run, tmp_path):
    """Files named inside an options file (PETSc inserts them itself) get the same checks; a
    cycle is an error, not a stack overflow."""
    before = snapshot(previous_run)
    for files, given, needle in NESTED:
        for name, text in files.items():
            (tmp_path / name).write_bytes(text.encode())
        one_error(run(["-options_file", given, "-output_dir", str(previous_run)], cwd=tmp_path,
                      ranks=ranks), needle)
    assert snapshot(previous_run) == before
    (tmp_path / "inner.txt").write_text("-steps 3\n")
    (tmp_path / "outer.txt").write_text("-options_file inner.txt\n-grid_n 16,16\n")
    r = run(["-options_file", "outer.txt", "-png_every", "0", "-output_dir", "o"], cwd=tmp_path,
            ranks=ranks)
    assert r.returncode == 0, r.stderr
    assert "grid 16x16" in r.stdout and "3 steps" in r.stdout, r.stdout


BAD_VALUES = [
    (["-steps", " "], '-steps " ": not an integer'),
    (["-seed", "  "], '-seed "  ": not an integer'),
    (["-dt", " "], '-dt " ": not a number'),
    (["-integrator", "ts "], '-integrator "ts ": unknown, allowed explicit, split, ts'),
    (["-output_name", "checkpoint"], "-output_name checkpoint: reserved for the checkpoint files"),
    (["-png_range_a", "-inf,inf"], "-png_range_a -inf,inf: needs finite lo < hi"),
    (["-png_range_a", "-1e308,1e308"], "-png_range_a -1e308,1e308: needs finite lo < hi"),
    (["-model", "custom", "-species", "A,a", "-rate_A", "1", "-rate_a", "0 - 5*a"],
     "-species a: given twice (species names are compared ignoring case"),
    (["-model", "custom", "-species", "a,a", "-rate_a", "1"], "-species a: given twice"),
    (["-integrator", "split", "-D_a", "1e20"],
     "-dt 0.5: 2e+20 times the explicit diffusion stability bound 2.5e-21, allowed at most 1e+12"),
    (["-integrator", "split", "-grid_L", "1e-160"], "-dt 0.5: inf times the explicit diffusion"),
    (["-integrator", "ts", "-D_a", "1e20"], "allowed at most 1e+12 times"),
    (["-integrator", "ts", "-ts_diffusion", "explicit", "-force_dt", "-dt", "1e308", "-steps",
      "10"], "-dt 1e+308: the end time -steps 10 times -dt overflows a double"),
    (["-dt", "1e-320"], "-dt 1e-320: out of range, allowed >= 2.22507e-308"),
    (["-dt", "0"], "-dt 0: out of range, allowed >= 2.22507e-308"),
    (["-layers", "16"], "-layers 16: 16 layers of turing's 2 species make 32, allowed at most 16 "
     "species (-layers 8 or fewer here)"),
    (["-layers", "2147483648"], "-layers 2147483648: out of range, allowed [1, 16]"),
    (["-steps", "99999999999999999999"], "-steps 99999999999999999999: out of range, allowed >= 0"),
    (["-integrator", "ts", "-ts_type", "theta", "-ts_theta_theta", "2"],
     "-ts_theta_theta 2: out of range, allowed [0, 1]"),
    (["-integrator", "ts", "-ts_max_snes_failures", "-5"],
     "-ts_max_snes_failures -5: out of range, allowed an integer >= -1"),
]


@pytest.mark.parametrize("case", BAD_VALUES, ids=[" ".join(c[0]) for c in BAD_VALUES])
def test_bad_values(case, previous_run, tmp_path):
    """Blank numbers, names that clash with other files or ignoring case, a colour range without
    a finite width, a diffusion number the implicit solves cannot resolve, an end time that
    overflows: one line, nothing written."""
    args, needle = case
    before = snapshot(previous_run)
    one_error(run(["-grid_n", "16,16", "-steps", "2"] + args + ["-output_dir", str(previous_run)],
                  cwd=tmp_path), needle)
    assert snapshot(previous_run) == before


@pytest.mark.parametrize("ranks", [1, 2])
def test_restart_from_a_non_finite_checkpoint(ranks, tmp_path):
    """A checkpoint holding a NaN is refused at the restart, not reported as a divergence later;
    the directory is left as it was."""
    out = tmp_path / "out"
    r = run(SMALL + ["-steps", "4", "-output_dir", str(out)], cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    ck = out / "checkpoint_0000004.vtkhdf"
    with h5py.File(ck, "r+") as h:
        b = h["VTKHDF/PointData/b"]
        v = np.array(b)
        v.flat[37] = np.nan
        b[...] = v
    before = snapshot(out)
    one_error(run(SMALL + ["-steps", "8", "-restart", "latest", "-output_dir", str(out)],
                  cwd=tmp_path, ranks=ranks),
              f"-restart {ck}: species b holds a non-finite value (nan)")
    assert snapshot(out) == before


def test_bad_files_in_values(previous_run, tmp_path):
    """Strokes and .series files nested absurdly deep (a stack overflow before), a number that
    overflows a double in a strokes file (an internal error before), a strokes "file" that is a
    directory, a -deck_dir that is a file, an infinite viscosity: one line each."""
    (tmp_path / "big.json").write_text(
        '{"strokes": [{"points": [[0.2,0.3],[0.5,1e400]]}], "units": "fraction"}')
    n = 100000
    (tmp_path / "deep.json").write_text('{"strokes": [{"points": ' + "[" * n + "]" * n + "}]}")
    (tmp_path / "deep.series").write_text('{"files": ' + "[" * n + "]" * n + "}")
    (tmp_path / "dir.json").mkdir()
    (tmp_path / "afile").write_text("x")
    fluid = ["-model", "custom", "-species", "dye", "-rate_dye", "0", "-D_dye", "0", "-grid_L",
             "1", "-grid_bc", "neumann", "-init_dye", "x<0.5", "-advect", "dye", "-dt", "0.01",
             "-fluid", "cavity"]
    cases = [
        (["-init_a", '4 + strokes("big.json")'],
         "strokes file big.json: number overflow parsing '1e400'"),
        (["-init_a", '4 + strokes("deep.json")'],
         "strokes file deep.json: nested 100003 levels deep, allowed at most 64"),
        (["-advect", "a", "-grid_bc", "neumann", "-velocity_file", "deep.series"],
         "-velocity_file deep.series: not a valid .series JSON file (nested 100001 levels deep"),
        (["-init_a", '4 + strokes("dir.json")'], "strokes file dir.json: not a regular file"),
        (["-deck_dir", "afile"], "-deck_dir afile: not a directory"),
        (fluid + ["-fluid_viscosity", "inf"], "-fluid_viscosity inf: out of range, allowed >= 0"),
    ]
    before = snapshot(previous_run)
    for args, needle in cases:
        one_error(run(SMALL + args + ["-output_dir", str(previous_run)], cwd=tmp_path), needle)
    assert snapshot(previous_run) == before


def test_options_file_works(tmp_path):
    (tmp_path / "o.txt").write_text("# plain PETSc format\n-grid_n 16,16\n-steps 3\n")
    (tmp_path / "o.yaml").write_text("png_every: 0\n")
    r = run(["-options_file", "o.txt", "-options_file", "o.yaml", "-steps", "2", "-output_dir",
             "o"], cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "grid 16x16" in r.stdout and "2 steps" in r.stdout, r.stdout


def test_long_values_are_whole(tmp_path):
    """Values over the old 4095-character buffer are read whole, from a deck and the command
    line (an expression of 6000 characters)."""
    expr = "4" + " + 0" * 1500
    deck = tmp_path / "long.yaml"
    deck.write_text('model: turing\ninit:\n  b: "%s"\n' % expr)
    r = run([str(deck), "-init_a", expr] + SMALL + ["-output_dir", "o"], cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    used = (tmp_path / "o/options_used.yaml").read_text()
    assert ('init_a: "%s"' % expr) in used and ('init_b: "%s"' % expr) in used


def test_long_output_dir_creates_nothing(tmp_path):
    deep = "d/" * 2100  # 4200 characters
    one_error(run(SMALL + ["-output_dir", deep], cwd=tmp_path), "-output_dir", "path of")
    assert not (tmp_path / "d").exists()
    one_error(run(SMALL + ["-output_dir", "x" * 300], cwd=tmp_path), "-output_dir",
              "directory name of 300 characters")
    assert os.listdir(tmp_path) == []


# --- values -------------------------------------------------------------------------------

VALUES = [
    ("assignment", "x = 5", ["-init_a x = 5", "assignment"]),
    ("comma_list", "1,2", ["-init_a 1,2", "comma-separated list"]),
    ("spots_huge", "spots(1e15, 0, 1)", ["-init_a", "n = 1e+15", "allowed an integer in [0, 100000]"]),
    ("spots_1e300", "spots(1e300, 1, 1)", ["-init_a", "n = 1e+300"]),
    ("spots_negative", "spots(-3, 1, 1)", ["-init_a", "n = -3"]),
    ("spots_fraction", "spots(2.5, 1, 1)", ["-init_a", "n = 2.5"]),
    ("spots_seed", "spots(3, 1, -1)", ["-init_a", "seed = -1"]),
]


@pytest.mark.parametrize("ranks", [1, 2])
@pytest.mark.parametrize("case", VALUES, ids=[c[0] for c in VALUES])
def test_bad_value(case, ranks, previous_run, tmp_path):
    _, value, needles = case
    before = snapshot(previous_run)
    one_error(run(SMALL + ["-init_a", value, "-output_dir", str(previous_run)], cwd=tmp_path,
                  ranks=ranks, timeout=60), *needles)
    assert snapshot(previous_run) == before


def test_comparisons_and_function_arguments_still_work(tmp_path):
    r = run(SMALL + ["-init_a", "x <= 8 ? 4 : (x == 9 ? 3 : max(1, 2))", "-init_b",
                     "4 + spots(3, 2, 7)", "-output_dir", "o"], cwd=tmp_path)
    assert r.returncode == 0, r.stderr


# --- restart ------------------------------------------------------------------------------

ATTRS = [("time", np.nan), ("time", np.inf), ("dt", np.inf), ("dt", -1.0), ("dt", np.nan),
         ("step", -5), ("level", 99), ("nranks", 0)]


@pytest.mark.parametrize("ranks", [1, 2])
@pytest.mark.parametrize("attr", ATTRS, ids=["%s=%s" % a for a in ATTRS])
@pytest.mark.parametrize("spec", ["file", "latest"])
def test_restart_attribute_out_of_range(attr, spec, ranks, previous_run, tmp_path):
    name, value = attr
    ckpt = previous_run / "checkpoint_0000002.vtkhdf"
    with h5py.File(ckpt, "r+") as f:
        a = f["morphogen"].attrs
        a[name] = np.array(value, dtype=a[name].dtype)
    before = snapshot(previous_run)
    restart = str(ckpt) if spec == "file" else "latest"
    one_error(run(SMALL + ["-steps", "4", "-restart", restart, "-output_dir", str(previous_run)],
                  cwd=tmp_path, ranks=ranks), "checkpoint_0000002.vtkhdf",
              "attribute /morphogen/%s" % name)
    assert snapshot(previous_run) == before


# --- help and version ---------------------------------------------------------------------

@pytest.mark.parametrize("flag", ["-h", "--help", "-help"])
def test_help_runs_nothing(flag, previous_run, tmp_path):
    before = snapshot(previous_run)
    r = run([flag, "-output_dir", str(previous_run), "-restart", "latest"], cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    out = r.stdout
    assert "Options read by this configuration" in out
    for group in ["Model and values:", "Grid:", "Time integration:", "Output:"]:
        assert group in out, out
    for generic in ["-png_range_<species>", "-source_<species>", "-dirichlet_<species>",
                    "-split_ordering", "-sequence_steps", "-help [petsc]", "Models (-model NAME)"]:
        assert generic in out, generic
    assert "-dt <0.5>" in out and "allowed >= 0" in out
    assert "PETSc Option Table" not in out and "-malloc" not in out, out[:3000]
    assert not re.search(r"\d\.\d{9,}", out), re.search(r".*\d\.\d{9,}.*", out).group(0)
    assert snapshot(previous_run) == before
    assert sorted(os.listdir(tmp_path)) == ["out"]


def test_help_petsc_shows_petsc_options(tmp_path):
    r = run(["-help", "petsc", "-integrator", "split", "-grid_n", "16,16"], cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "-malloc" in r.stdout or "PETSc" in r.stdout
    assert "-diffusion_ksp_type" in r.stdout
    assert "Options read by this configuration" in r.stdout
    assert os.listdir(tmp_path) == []


@pytest.mark.parametrize("flag", ["--version", "-version"])
def test_version(flag, tmp_path):
    r = run([flag], cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith("morphogen 0."), r.stdout
    assert "PETSc" in r.stdout or "Petsc" in r.stdout
    assert os.listdir(tmp_path) == []


# --- messages -----------------------------------------------------------------------------

def test_param_of_other_model_names_it(tmp_path):
    one_error(run(SMALL + ["-params_F", "0.03", "-output_dir", "o"], cwd=tmp_path),
              "-params_F 0.03: unknown option", "F is a parameter of gray_scott", "not of turing")
    assert not (tmp_path / "o").exists()


def test_sweep_without_sweep_section(tmp_path):
    deck = tmp_path / "plain.yaml"
    deck.write_text("model: turing\ngrid:\n  n: 16,16\nsteps: 2\n")
    one_error(run(["sweep", str(deck), "-output_dir", "o"], cwd=tmp_path),
              "plain.yaml: no sweep: section")
    assert not (tmp_path / "o").exists()


def test_numbers_for_people(tmp_path):
    r = run(SMALL + ["-grid_L", "10,10", "-grid_n", "30,30", "-dt", "0.01", "-output_dir", "o"],
            cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    header = [l for l in r.stdout.splitlines() if "explicit bound" in l][0]
    assert not re.search(r"\d\.\d{7,}", header), header
    one_error(run(SMALL + ["-D_a", "-1", "-output_dir", "o2"], cwd=tmp_path), "-D_a -1",
              "allowed >= 0")
    one_error(run(SMALL + ["-dt", "-1", "-output_dir", "o2"], cwd=tmp_path), "-dt")


def test_diffusion_ksp_option_named(tmp_path):
    one_error(run(SMALL + ["-integrator", "split", "-diffusion_ksp_rtol", "abc", "-output_dir", "o"],
                  cwd=tmp_path), "-diffusion_ksp_rtol abc")
    assert not (tmp_path / "o").exists()
