"""The default deck (Sanderson Fig. 1) forms spots on 2 ranks in well under a minute, and the
stripes deck (Fig. 3) forms stripes: many round, separate spots versus few long components."""
import os
import time

from conftest import SOURCE, run
from patterns import describe


def test_default_deck_forms_spots_on_two_ranks(workdir):
    t0 = time.time()
    proc = run(["-output_dir", str(workdir / "spots")], cwd=workdir, ranks=2, timeout=120)
    elapsed = time.time() - t0
    assert proc.returncode == 0, proc.stderr
    assert elapsed < 60, f"default run took {elapsed:.1f} s"
    d = describe(str(workdir / "spots" / "a_final.png"))
    assert d["contrast"] > 0.3, d
    assert d["count"] > 100, d  # 256^2 with spots ~19 cells apart: about 180 spots
    assert d["median_elongation"] < 1.6, d
    assert d["largest_fraction"] < 0.01, d


def test_stripes_deck_forms_stripes(workdir):
    deck = os.path.join(SOURCE, "input", "turing_stripes.yaml")
    proc = run([deck, "-output_dir", str(workdir / "stripes")], cwd=workdir, ranks=2, timeout=600)
    assert proc.returncode == 0, proc.stderr
    d = describe(str(workdir / "stripes" / "a_final.png"))
    assert d["contrast"] > 0.3, d
    assert d["median_elongation"] > 2.5 or d["largest_fraction"] > 0.05, d
