"""The Hopf line of the sweep stability map and phase_diagram.py: for the Brusselator the
homogeneous state (alpha, beta/alpha) loses stability through a Hopf bifurcation at
beta = 1 + alpha^2 (trace J = 0, det J = alpha^2 > 0). The complex-eigenvalue region ends at
beta = (1 + alpha)^2, which is no stability boundary and must not be drawn."""
import json
import os
import subprocess
import sys

import numpy as np

from conftest import SOURCE, run


def test_brusselator_hopf_region_is_trace_positive(tmp_path):
    out = tmp_path / "sw"
    deck = os.path.join(SOURCE, "input", "brusselator_sweep.yaml")
    r = run(["sweep", deck, "-grid_n", "16,16", "-grid_L", "48", "-steps", "10",
             "-sweep_params_alpha", "linspace(1, 3, 5)", "-sweep_params_beta", "linspace(1, 20, 8)",
             "-output_dir", str(out)], cwd=tmp_path, ranks=2)
    assert r.returncode == 0, r.stdout + r.stderr
    sm = json.loads((out / "sweep.json").read_text())["stability_map"]
    alpha, beta = (np.asarray(a) for a in sm["axes"])
    A, B = np.meshgrid(alpha, beta)  # first axis fastest
    region = np.asarray(sm["hopf_region"]).reshape(B.shape)
    complex_unstable = np.asarray(sm["hopf"]).reshape(B.shape)
    want = B > 1 + A ** 2
    clear = np.abs(B - (1 + A ** 2)) > 1e-6
    assert (region == want)[clear].all()
    # the old flag stops at beta = (1 + alpha)^2: above it the eigenvalues are real (and positive)
    above = B > (1 + A) ** 2 + 1e-6
    assert above.any() and not complex_unstable[above].any() and region[above].all()
    fig = subprocess.run([sys.executable, os.path.join(SOURCE, "postproc", "phase_diagram.py"), str(out)],
                         capture_output=True, text=True)
    assert fig.returncode == 0, fig.stderr
    assert "hopf" in fig.stdout and (out / "phase_classes.png").exists()
