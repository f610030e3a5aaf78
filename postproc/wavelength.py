#!/usr/bin/python3
"""Dominant wavelength of a pattern from its radially averaged power spectrum.

    /usr/bin/python3 postproc/wavelength.py FILE [FILE ...] [--spacing H] [--species S]

FILE is a PNG image or a VTKHDF snapshot/checkpoint (*.vtkhdf: the field of --species, default
the first; 3-D: the middle z slice). A PNG's grey level (luminance; monotone in the field for
morphogen's viridis, magma and grey images) or the snapshot's values are de-meaned, Fourier
transformed (the domain is taken as periodic), and the power is averaged over rings of integer
wavenumber |k| (in cycles per domain). The peak ring, refined by a power-weighted mean over its
neighbours, gives the wavelength L / k in cells (PNG; in length units with --spacing) or in the
snapshot's length units (its spacing). Prints one line per file: path, wavelength, peak ring
(and wavelength_cells for snapshots).
"""
import argparse
import os
import sys

import matplotlib.image as mpimg
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))


def spectrum_wavelength(g):
    """(wavelength in rows of g, peak ring) of a 2-D array."""
    g = np.asarray(g, dtype=float)
    g = g - g.mean()
    ny, nx = g.shape
    p = np.abs(np.fft.fft2(g)) ** 2
    ky = np.fft.fftfreq(ny) * ny
    kx = np.fft.fftfreq(nx) * nx
    # wavenumber in cycles per (square) domain, scaled so non-square images work
    kk = np.sqrt((kx[None, :] * (ny / nx)) ** 2 + ky[:, None] ** 2)
    ring = np.rint(kk).astype(int)
    kmax = min(nx, ny) // 2
    power = np.bincount(ring.ravel(), weights=p.ravel(), minlength=kmax + 1)[: kmax + 1]
    counts = np.bincount(ring.ravel(), minlength=kmax + 1)[: kmax + 1]
    spectrum = power / np.maximum(counts, 1)
    spectrum[0] = 0.0
    peak = int(np.argmax(spectrum))
    if peak == 0:
        raise ValueError("no structure (uniform field)")
    lo, hi = max(1, peak - 1), min(kmax, peak + 1)
    ks = np.arange(lo, hi + 1)
    kpeak = float(np.sum(ks * spectrum[lo:hi + 1]) / np.sum(spectrum[lo:hi + 1]))
    return ny / kpeak, peak


def dominant_wavelength(path, spacing=1.0):
    """(wavelength, peak ring) of a PNG image, in cells times spacing."""
    img = mpimg.imread(path)
    g = img[..., :3] @ np.array([0.2126, 0.7152, 0.0722]) if img.ndim == 3 else img
    lam, peak = spectrum_wavelength(g)
    return lam * spacing, peak


def snapshot_wavelength(path, species=None):
    """(wavelength in length units, in cells, peak ring, species) of a VTKHDF file's field."""
    import morphogen_h5 as mh  # h5py only when needed
    snap = mh.read_snapshot(path)
    s = species or snap["species"][0]
    if s not in snap["fields"]:
        raise ValueError(f"no species {s!r} (has {', '.join(snap['species'])})")
    a = np.asarray(snap["fields"][s], dtype=float)
    if a.ndim == 3:
        a = a[a.shape[0] // 2]
    cells, peak = spectrum_wavelength(a)
    return cells * snap["spacing3"][1], cells, peak, s


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("files", nargs="+")
    ap.add_argument("--spacing", type=float, default=1.0, help="PNG: grid spacing h (default 1: cells)")
    ap.add_argument("--species", default=None, help="VTKHDF: species (default: the first)")
    args = ap.parse_args(argv)
    for path in args.files:
        try:
            if path.endswith((".vtkhdf", ".hdf", ".h5")):
                lam, cells, peak, s = snapshot_wavelength(path, args.species)
                print(f"{path} species={s} wavelength={lam:.4f} wavelength_cells={cells:.4f} "
                      f"peak_ring={peak}")
            else:
                lam, peak = dominant_wavelength(path, args.spacing)
                print(f"{path} wavelength={lam:.4f} peak_ring={peak}")
        except (OSError, ValueError) as e:  # MorphogenH5Error is a ValueError
            sys.exit(f"wavelength: error: {path}: {e}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
