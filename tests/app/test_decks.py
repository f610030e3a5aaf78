"""Every shipped deck (input/*.yaml) is documented and runs: it opens with a header comment
that names its paper or source and what to expect, follows the deck conventions (output_dir
named after the deck, 4-6 intermediate images), and a 20-step run on 1 rank exits 0 within
120 s and writes a final PNG per species plus options_used.yaml. The options_used.yaml a run
writes is itself a deck that resolves to the same options and gives the same images.
The full-length runs (minutes) are not repeated here; each header says what they show."""
import glob
import os
import re
import time

import pytest
import yaml

from conftest import SOURCE, run

DECKS = sorted(glob.glob(os.path.join(SOURCE, "input", "*.yaml")))
IDS = [os.path.splitext(os.path.basename(d))[0] for d in DECKS]


def is_sweep(path):
    with open(path) as f:
        return "sweep" in yaml.safe_load(f)


# Single-run decks, and sweep decks (a `sweep:` section, run with `morphogen sweep`).
RUNS = [d for d in DECKS if not is_sweep(d)]
RUN_IDS = [os.path.splitext(os.path.basename(d))[0] for d in RUNS]
SWEEPS = [d for d in DECKS if is_sweep(d)]
SWEEP_IDS = [os.path.splitext(os.path.basename(d))[0] for d in SWEEPS]

# Papers and authors a deck header may cite (the papers in shared/papers, their models' authors).
SOURCES = re.compile(
    r"Sanderson|Garrity|Pearson|Lawlor|Witkin|Kass|Turk|Turing|Gray-Scott|Sims|Barkley|"
    r"FitzHugh|Nagumo|Gierer|Meinhardt|Schnakenberg|Brusselator|Prigogine|Oregonator|"
    r"Tyson|Murray|Stable Advection-Reaction-Diffusion", re.IGNORECASE)


def header(path):
    """The leading block of comment lines."""
    lines = []
    with open(path) as f:
        for line in f:
            if not line.startswith("#"):
                break
            lines.append(line)
    return lines


def load_options(path):
    """options_used.yaml as {option: value string}."""
    with open(path) as f:
        return {k: str(v) for k, v in yaml.safe_load(f).items()}


@pytest.fixture(scope="module")
def model_species():
    """{model: [species]} from the model table printed by -help."""
    proc = run(["-help"], cwd=SOURCE, timeout=60)
    assert proc.returncode == 0, proc.stderr
    table = proc.stdout.split("Models (-model NAME):", 1)[1]
    species, model = {}, None
    for line in table.splitlines():
        m = re.match(r"^  (\w+)\s", line)
        if m:
            model = m.group(1)
            species[model] = []
            continue
        m = re.match(r"^\s+species\s+(\S+)", line)
        if m and model:
            species[model].append(m.group(1))
    assert "turing" in species and species["turing"] == ["a", "b"], species
    return species


def test_decks_found():
    assert len(DECKS) >= 10, f"expected the shipped decks in {SOURCE}/input, found {DECKS}"


@pytest.mark.parametrize("deck", DECKS, ids=IDS)
def test_deck_header_and_conventions(deck):
    name = os.path.splitext(os.path.basename(deck))[0]
    head = header(deck)
    assert head and head[0].startswith("#"), f"{name}: the first line must be a comment"
    text = "".join(head)
    assert SOURCES.search(head[0]) or SOURCES.search(text), \
        f"{name}: the header names no paper or source"
    assert "should see" in text, f"{name}: the header does not say what the user should see"
    with open(deck) as f:
        cfg = yaml.safe_load(f)
    assert str(cfg.get("output_dir")) == name, f"{name}: output_dir should be the deck name"
    if "sweep" in cfg:
        assert f"morphogen sweep input/{name}.yaml" in text, f"{name}: say how to run the sweep"
        return
    steps, every = int(cfg["steps"]), int(cfg["png_every"])
    assert 4 <= steps // every <= 6, f"{name}: {steps} steps / png_every {every} images"


@pytest.mark.parametrize("deck", RUNS, ids=RUN_IDS)
def test_deck_runs(deck, workdir, model_species):
    out = workdir / "out"
    t0 = time.time()
    proc = run([deck, "-steps", "20", "-png_every", "10", "-output_dir", str(out)],
               cwd=workdir, timeout=120)
    elapsed = time.time() - t0
    assert proc.returncode == 0, proc.stderr
    assert elapsed < 120, f"20 steps took {elapsed:.1f} s"
    assert (out / "options_used.yaml").is_file()
    used = load_options(out / "options_used.yaml")
    with open(deck) as f:
        cfg = yaml.safe_load(f)
    species = model_species[used["model"]]
    if used["model"] == "custom":  # a user-defined model: the deck's own species
        species = [x.strip() for x in used["species"].split(",")]
    if int(used.get("layers", "1")) > 1:  # coupled layers: a1, b1, a2, b2, ...
        species = [f"{x}{l}" for l in range(1, int(used["layers"]) + 1) for x in species]
    if "png_species" in cfg:
        species = [s.strip() for s in str(cfg["png_species"]).split(",")]
    assert used["png_species"].split(",") == species, used["png_species"]
    for s in species:
        for tag in ("0000010", "final"):
            png = out / f"{s}_{tag}.png"
            assert png.is_file() and png.stat().st_size > 0, f"missing {png.name}"


@pytest.mark.parametrize("deck", RUNS, ids=RUN_IDS)
def test_options_used_is_a_deck(deck, workdir):
    first, second = workdir / "first", workdir / "second"
    proc = run([deck, "-steps", "2", "-output_dir", str(first)], cwd=workdir, timeout=120)
    assert proc.returncode == 0, proc.stderr
    proc = run([str(first / "options_used.yaml"), "-steps", "2", "-output_dir", str(second)],
               cwd=workdir, timeout=120)
    assert proc.returncode == 0, proc.stderr
    a = load_options(first / "options_used.yaml")
    b = load_options(second / "options_used.yaml")
    assert b.pop("output_dir") == str(second)
    assert a.pop("output_dir") == str(first)
    assert a == b
    finals = sorted(p.name for p in first.glob("*_final.png"))
    assert finals and finals == sorted(p.name for p in second.glob("*_final.png"))
    for name in finals:
        assert (first / name).read_bytes() == (second / name).read_bytes(), \
            f"{name} differs when rerun from options_used.yaml"


@pytest.mark.parametrize("deck", SWEEPS, ids=SWEEP_IDS)
def test_sweep_deck_runs(deck, workdir):
    """A sweep deck runs every point (20 steps each, 2 ranks), and the options_used.yaml it
    writes reruns as the same sweep; as a plain run it is refused with a pointer to `sweep`."""
    import json
    first, second = workdir / "first", workdir / "second"
    proc = run(["sweep", deck, "-steps", "20", "-output_dir", str(first)], workdir, 2, timeout=600)
    assert proc.returncode == 0, proc.stderr
    with open(first / "sweep.json") as f:
        a = json.load(f)
    npoints = int(re.search(r"sweep: (\d+) points", proc.stdout).group(1))
    assert a["finished"] == a["points"] == npoints > 1
    proc = run(["sweep", str(first / "options_used.yaml"), "-steps", "20", "-output_dir",
                str(second)], workdir, 2, timeout=600)
    assert proc.returncode == 0, proc.stderr
    with open(second / "sweep.json") as f:
        b = json.load(f)
    assert [r["class"] for r in a["records"]] == [r["class"] for r in b["records"]]
    proc = run([deck, "-steps", "2", "-output_dir", "plain"], workdir)
    assert proc.returncode == 1 and "morphogen sweep" in proc.stderr, proc.stderr
