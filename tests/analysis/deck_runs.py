"""Shared by the classifier deck tests: full-length deck runs on 2 ranks, each run once per
module, and their summary.json."""
import json
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "app"))
from conftest import SOURCE, run  # noqa: E402


def deck_runner(tmp_path_factory):
    """deck name -> the output directory of its full-length run on 2 ranks (run once)."""
    runs = {}

    def get(deck):
        if deck not in runs:
            cwd = tmp_path_factory.mktemp(deck)
            r = run([os.path.join(SOURCE, "input", deck + ".yaml"), "-output_dir", "o",
                     "-png_every", "0"], cwd, 2, timeout=900)
            assert r.returncode == 0, r.stdout[-1500:] + r.stderr[-1500:]
            runs[deck] = cwd / "o"
        return runs[deck]

    return get


def summary(out):
    with open(out / "summary.json") as f:
        return json.load(f)
