#!/usr/bin/env python3
"""The spec's ray at one pixel, and what it hits, computed by brute force (a third opinion).

    ray_at.py SCENE.toml X Y

Pixel (X, Y) (top-left origin) has its centre at screen (s, t) = ((X + 0.5) / W, 1 - (Y + 0.5) / H);
the first projection triangle whose screen triangle holds it gives barycentrics b and the ray
tripoint(b) + t * trinorm(b), t >= 0 (trinorm not renormalised). Every scene triangle is tested
(Moller-Trumbore, two-sided) and the nearest hit's object id is printed (0 = none).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import flexscene


def pixel_ray(proj: flexscene.Trilinear, s: float, t: float):
    """(origin, direction, triangle index, barycentrics), or None outside every triangle."""
    for k, tri in enumerate(proj.triangles):
        a, b, c = proj.screen[tri]
        m = np.array([b - a, c - a]).T
        if abs(np.linalg.det(m)) < 1e-300:
            continue
        l1, l2 = np.linalg.solve(m, np.array([s, t]) - a)
        bary = np.array([1 - l1 - l2, l1, l2])
        if bary.min() >= -1e-12:
            return bary @ proj.points[tri], bary @ proj.normals[tri], k, bary
    return None


def first_hit(scene: flexscene.Scene, o: np.ndarray, d: np.ndarray):
    """(t, object id) of the nearest hit with t >= 0, or (inf, 0)."""
    best = (np.inf, 0)
    for oid, _, tris in scene.objects:
        v0, e1, e2 = tris[:, 0], tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]
        p = np.cross(d, e2)
        det = np.einsum("ij,ij->i", e1, p)
        ok = np.abs(det) > 1e-14
        inv = np.where(ok, 1 / np.where(ok, det, 1), 0)
        tv = o - v0
        u = np.einsum("ij,ij->i", tv, p) * inv
        q = np.cross(tv, e1)
        v = (q @ d) * inv
        t = np.einsum("ij,ij->i", e2, q) * inv
        hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t >= 0)
        if hit.any() and t[hit].min() < best[0]:
            best = (float(t[hit].min()), oid)
    return best


def main() -> int:
    scene = flexscene.load(Path(sys.argv[1]))
    x, y = int(sys.argv[2]), int(sys.argv[3])
    s, t = (x + 0.5) / scene.width, 1 - (y + 0.5) / scene.height
    ray = pixel_ray(scene.projection, s, t)
    if ray is None:
        print(f"pixel ({x}, {y}) screen ({s:.6f}, {t:.6f}): no projection triangle: background, id 0")
        return 0
    o, d, k, bary = ray
    dist, oid = first_hit(scene, o, d)
    print(f"pixel ({x}, {y}) screen ({s:.6f}, {t:.6f}) triangle {k} b {np.round(bary, 6)}\n"
          f"  origin {np.round(o, 6)} direction {np.round(d, 6)}\n  first hit t = {dist:.6g}: id {oid}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
