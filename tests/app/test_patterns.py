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


def test_split_with_ten_times_the_explicit_bound_forms_the_same_spots(workdir):
    """Sanderson Fig. 1 at 128^2: explicit (dt 0.5, 50,000 steps) against the split integrator
    with dt 10 = 10x the explicit bound (2,500 steps, same final time t = 25,000): both form
    spots, and the dominant wavelengths agree within 5 %."""
    import sys

    sys.path.insert(0, os.path.join(SOURCE, "postproc"))
    from wavelength import dominant_wavelength

    common = ["-grid_n", "128,128", "-png_every", "0", "-png_species", "a"]
    ex = run(common + ["-output_dir", str(workdir / "explicit")], cwd=workdir, ranks=2)
    assert ex.returncode == 0, ex.stderr
    sp = run(common + ["-integrator", "split", "-dt", "10", "-steps", "2500",
                       "-output_dir", str(workdir / "split")], cwd=workdir, ranks=2, timeout=600)
    assert sp.returncode == 0, sp.stderr
    lam_ex, _ = dominant_wavelength(str(workdir / "explicit" / "a_final.png"))
    lam_sp, _ = dominant_wavelength(str(workdir / "split" / "a_final.png"))
    print(f"dominant wavelength: explicit {lam_ex:.3f}, split dt=10 {lam_sp:.3f}")
    assert abs(lam_sp - lam_ex) / lam_ex < 0.05
    d = describe(str(workdir / "split" / "a_final.png"))
    assert d["count"] > 25 and d["median_elongation"] < 1.6, d


def test_grid_sequencing_forms_spots_sooner(workdir):
    """Coarse-to-fine (64^2 -> 128^2 -> 256^2, 5,000 steps on each level, 15,000 in all) gives
    spots at the full resolution; a single-grid run needs about 30,000 steps."""
    proc = run(["-sequence_levels", "3", "-sequence_steps", "5000,5000", "-steps", "5000",
                "-png_every", "0", "-output_dir", str(workdir / "seq")], cwd=workdir, ranks=2)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.count("level ") == 3
    d = describe(str(workdir / "seq" / "a_final.png"))
    assert d["count"] > 100 and d["median_elongation"] < 1.6, d
