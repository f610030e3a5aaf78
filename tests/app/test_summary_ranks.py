"""summary.json on any number of ranks: each species' field is gathered to, and classified on,
rank s mod size (src/app/run_output.cpp, RunOutput::classify_all) and the results are sent to
rank 0. The fields are bitwise those of one rank (explicit run), so every species' class and
metrics must be exactly the one-rank ones, in the right species' entry, whether a rank has
several species (5 species on 2 ranks: rounds {a, b}, {c, d}, {e}) or none (2 species on 3
ranks), and in 3-D, where a species' root need not own the middle z slice (4 ranks)."""
import json
import os

import pytest

from conftest import SOURCE, error_lines, run

CASES = {
    # five species of distinct fields (the three-layer Oregonator, a few hundred steps)
    "oregonator_5": [os.path.join(SOURCE, "input", "oregonator_three_layer.yaml"), "-steps", "300"],
    # two species, spots forming on a small grid
    "turing_2": ["-grid_n", "64,64", "-steps", "400"],
    # 3-D: the middle z slice, which not every rank (nor every species' root) owns
    "turing_3d": [os.path.join(SOURCE, "input", "turing_spots_3d.yaml"), "-grid_n", "24,24,24",
                  "-steps", "100"],
}


def summary(workdir, case, ranks):
    out = workdir / f"{case}_{ranks}"
    proc = run(CASES[case] + ["-output_dir", str(out)], workdir, ranks=ranks)
    assert proc.returncode == 0, error_lines(proc)
    with open(out / "summary.json") as f:
        return json.load(f)["species"]


@pytest.mark.parametrize("case,ranks", [("oregonator_5", 2), ("oregonator_5", 3),
                                        ("turing_2", 2), ("turing_2", 3), ("turing_3d", 4)])
def test_every_species_classified_as_on_one_rank(workdir, case, ranks):
    one = summary(workdir, case, 1)
    many = summary(workdir, case, ranks)
    assert list(many) == list(one)
    for name, ref in one.items():
        got = many[name]
        assert got["class"] == ref["class"], name
        assert got["reason"] == ref["reason"], name
        assert got["metrics"] == ref["metrics"], name
        assert ("dynamics" in got) == ("dynamics" in ref), name
    # the species' fields differ, so a result filed under the wrong species would show
    metrics = [json.dumps(v["metrics"], sort_keys=True) for v in one.values()]
    assert len(set(metrics)) == len(metrics)
