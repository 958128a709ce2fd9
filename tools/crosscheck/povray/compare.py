"""Pixel-by-pixel comparison of two object-id images."""

from __future__ import annotations

from collections import Counter

import numpy as np


def edge_mask(ids: np.ndarray) -> np.ndarray:
    """Pixels within 1 px (8-neighbourhood) of a pixel with another id."""
    h, w = ids.shape
    pad = np.pad(ids, 1, mode="edge")
    mask = np.zeros((h, w), bool)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            mask |= pad[1 + dy : 1 + dy + h, 1 + dx : 1 + dx + w] != ids
    return mask


def regions(mask: np.ndarray) -> list[list[tuple[int, int]]]:
    """8-connected components of a boolean mask, as lists of (y, x)."""
    seen = np.zeros_like(mask)
    out = []
    for y0, x0 in zip(*np.nonzero(mask)):
        if seen[y0, x0]:
            continue
        stack, comp = [(y0, x0)], []
        seen[y0, x0] = True
        while stack:
            y, x = stack.pop()
            comp.append((y, x))
            for dy in (-1, 0, 1):
                for dx in (-1, 0, 1):
                    yy, xx = y + dy, x + dx
                    if 0 <= yy < mask.shape[0] and 0 <= xx < mask.shape[1] and mask[yy, xx] and not seen[yy, xx]:
                        seen[yy, xx] = True
                        stack.append((yy, xx))
        out.append(comp)
    return out


def compare(a: np.ndarray, b: np.ndarray, max_regions: int = 8) -> dict:
    """Agreement of id images a and b: all pixels, and away from id edges of either image;
    the largest disagreeing regions away from edges with their bounding boxes and id pairs."""
    if a.shape != b.shape:
        raise ValueError(f"image sizes differ: {a.shape} vs {b.shape}")
    differ = a != b
    interior = ~(edge_mask(a) | edge_mask(b))
    bad = differ & interior
    comps = sorted(regions(bad), key=len, reverse=True)
    listed = []
    for comp in comps[:max_regions]:
        ys, xs = zip(*comp)
        pairs = Counter((int(a[y, x]), int(b[y, x])) for y, x in comp).most_common(3)
        listed.append({"pixels": len(comp), "x": [int(min(xs)), int(max(xs))],
                       "y": [int(min(ys)), int(max(ys))], "ids": pairs})
    return {
        "pixels": int(a.size),
        "agree_all": float(1 - differ.mean()),
        "differ_all": int(differ.sum()),
        "interior_pixels": int(interior.sum()),
        "agree_interior": float(1 - bad.sum() / max(interior.sum(), 1)),
        "differ_interior": int(bad.sum()),
        "regions": len(comps),
        "largest_regions": listed,
    }
