"""Crude pattern measures on a morphogen PNG (numpy only), for end-to-end checks that a deck
forms the pattern its header promises. The viridis map is monotone in luminance, so the
image's grey level orders the field values."""
from collections import deque

import matplotlib.image as mpimg
import numpy as np


def grey(path):
    img = mpimg.imread(path)[..., :3]
    return img @ np.array([0.2126, 0.7152, 0.0722])


def components(mask):
    """4-connected components of a boolean mask (periodic in both axes): list of (ys, xs)."""
    ny, nx = mask.shape
    seen = np.zeros_like(mask, dtype=bool)
    comps = []
    for y0, x0 in zip(*np.nonzero(mask)):
        if seen[y0, x0]:
            continue
        q = deque([(y0, x0)])
        seen[y0, x0] = True
        ys, xs = [], []
        while q:
            y, x = q.popleft()
            ys.append(y)
            xs.append(x)
            for dy, dx in ((1, 0), (-1, 0), (0, 1), (0, -1)):
                yy, xx = (y + dy) % ny, (x + dx) % nx
                if mask[yy, xx] and not seen[yy, xx]:
                    seen[yy, xx] = True
                    q.append((yy, xx))
        comps.append((np.array(ys), np.array(xs)))
    return comps


def elongation(ys, xs):
    """Ratio of the principal axes of a component (1 for a disk), ignoring periodic wrap."""
    if len(ys) < 3:
        return 1.0
    c = np.cov(np.vstack([ys, xs]).astype(float))
    ev = np.sort(np.linalg.eigvalsh(c))
    return float(np.sqrt(max(ev[1], 1e-12) / max(ev[0], 1e-12)))


def describe(path):
    """Threshold at the midpoint of the grey range; measure the minority phase."""
    g = grey(path)
    mid = 0.5 * (g.min() + g.max())
    mask = g < mid
    if mask.mean() > 0.5:
        mask = ~mask
    comps = [c for c in components(mask) if len(c[0]) >= 4]
    el = [elongation(*c) for c in comps]
    largest = max((len(c[0]) for c in comps), default=0)
    return {
        "contrast": float(g.max() - g.min()),
        "count": len(comps),
        "median_elongation": float(np.median(el)) if el else 0.0,
        "largest_fraction": largest / mask.size,
    }
