"""postproc/montage.py assembles a run's snapshots into one figure, ordered by step."""
import os
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "app"))
from conftest import SOURCE, run  # noqa: E402

import matplotlib.image as mpimg  # noqa: E402


def test_montage_of_a_short_run(tmp_path):
    out = tmp_path / "run"
    proc = run(["-grid_n", "32,32", "-steps", "30", "-png_every", "10", "-output_dir", str(out)], cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    script = os.path.join(SOURCE, "postproc", "montage.py")
    res = subprocess.run([sys.executable, script, str(out), "--species", "b"], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    img = mpimg.imread(str(out / "montage_b.png"))
    assert img.shape[0] > 100 and img.shape[1] > 3 * 100  # three panels side by side


def test_montage_missing_dir(tmp_path):
    script = os.path.join(SOURCE, "postproc", "montage.py")
    res = subprocess.run([sys.executable, script, str(tmp_path / "nope")], capture_output=True, text=True)
    assert res.returncode != 0 and "no such directory" in res.stderr


def test_plot_convergence(tmp_path):
    csv = tmp_path / "convergence.csv"
    csv.write_text("a,space,1,0.1,1e-2,2.0\na,space,1,0.05,2.5e-3,2.0\nb,time,2,0.1,1e-3,1.0\nb,time,2,0.05,5e-4,1.0\n")
    script = os.path.join(SOURCE, "postproc", "plot_convergence.py")
    out = tmp_path / "c.png"
    res = subprocess.run([sys.executable, script, str(csv), "--out", str(out)], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    img = mpimg.imread(str(out))
    assert img.shape[1] > img.shape[0]  # two panels side by side
