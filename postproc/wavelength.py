#!/usr/bin/python3
"""Dominant wavelength of a pattern image from its radially averaged power spectrum.

    /usr/bin/python3 postproc/wavelength.py IMAGE.png [IMAGE2.png ...] [--spacing H]

The image's grey level (luminance; monotone in the field for morphogen's viridis images) is
de-meaned, Fourier transformed (the domain is taken as periodic), and the power is averaged
over rings of integer wavenumber |k| (in cycles per domain). The peak ring, refined by a
power-weighted mean over its neighbours, gives the wavelength  L / k  in cells (or in length
units with --spacing). Prints one line per image: path, wavelength, peak ring.
"""
import argparse
import sys

import matplotlib.image as mpimg
import numpy as np


def dominant_wavelength(path, spacing=1.0):
    img = mpimg.imread(path)
    g = img[..., :3] @ np.array([0.2126, 0.7152, 0.0722]) if img.ndim == 3 else img
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
    lo, hi = max(1, peak - 1), min(kmax, peak + 1)
    ks = np.arange(lo, hi + 1)
    kpeak = float(np.sum(ks * spectrum[lo:hi + 1]) / np.sum(spectrum[lo:hi + 1]))
    return ny * spacing / kpeak, peak


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("images", nargs="+")
    ap.add_argument("--spacing", type=float, default=1.0, help="grid spacing h (default 1: cells)")
    args = ap.parse_args(argv)
    for path in args.images:
        try:
            lam, peak = dominant_wavelength(path, args.spacing)
        except (OSError, ValueError) as e:
            sys.exit(f"wavelength: error: {path}: {e}")
        print(f"{path} wavelength={lam:.4f} peak_ring={peak}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
