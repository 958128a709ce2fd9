#!/usr/bin/env python3
"""Writes random trilinear test scenes (not in the repository) for crosscheck.py.

    gen_scenes.py OUT_DIR [--seed 1] [--models scenes/models]

Each scene is a projection mesh of 2 to 50 triangles over a grid of screen cells (some cells
left empty, so that uncovered pixels show the background), with a planar or curved base and
unit diverging, converging (rays cross in the scene; unequal lengths), randomly crossing
(unit) or unequal-length (0.3 to 3 times) ray directions, looking at the cube-floor scene plus a UV sphere (OBJ written here) and the
repository's octahedron (OBJ) and pyramid (ASCII PLY). Also: the cube-floor scene through a
fan, a base that cuts through the cube (rays start inside it), and a pinhole (collapsed base).
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

OBJECTS = """
[[object]]
name = "floor"
shape = "plane"
size = [8.0, 8.0]

[[object]]
name = "cube"
shape = "box"
size = [2.0, 2.0, 2.0]
translate = [0.0, 1.0, 0.0]
rotate = [0.0, 30.0, 0.0]

[[object]]
name = "sphere"
shape = "mesh"
file = "sphere.obj"
translate = [2.2, 0.8, 1.0]

[[object]]
name = "octahedron"
shape = "mesh"
file = "{models}/octahedron.obj"
translate = [-2.2, 1.0, 0.8]
rotate = [10.0, 20.0, 0.0]
scale = 0.8

[[object]]
name = "pyramid"
shape = "mesh"
file = "{models}/pyramid.ply"
translate = [0.5, 0.0, 2.6]
scale = 0.6
"""


def uv_sphere(radius=0.8, rings=12, segments=24) -> str:
    lines = []
    for i in range(rings + 1):
        th = math.pi * i / rings
        for j in range(segments):
            ph = 2 * math.pi * j / segments
            lines.append(f"v {radius * math.sin(th) * math.cos(ph):.9f} {radius * math.cos(th):.9f} "
                         f"{radius * math.sin(th) * math.sin(ph):.9f}")
    for i in range(rings):
        for j in range(segments):
            a, b = i * segments + j + 1, i * segments + (j + 1) % segments + 1
            c, d = a + segments, b + segments
            lines.append(f"f {a} {b} {d} {c}")
    return "\n".join(lines) + "\n"


def grid_mesh(rng, nx, ny, keep):
    """Screen grid nx x ny cells (2 triangles each), interior vertices jittered; cells kept
    with probability `keep` (at least one). Returns screen (k,2) and triangles (m,3)."""
    s = np.array([[i / nx, j / ny] for j in range(ny + 1) for i in range(nx + 1)])
    inner = (s > 0) & (s < 1)
    s += np.where(inner, rng.uniform(-0.3, 0.3, s.shape) / np.array([nx, ny]), 0)
    tris = []
    for j in range(ny):
        for i in range(nx):
            if tris and rng.random() > keep:
                continue
            a = j * (nx + 1) + i
            b, c, d = a + 1, a + nx + 2, a + nx + 1
            tris += [[a, b, c], [a, c, d]] if rng.random() < 0.5 else [[a, b, d], [b, c, d]]
    return s, np.array(tris)


def base_points(rng, s, curved):
    """Base over the screen: a plane patch at z = 6 or a bent (cylinder/sphere-like) patch."""
    x, y = (s[:, 0] - 0.5) * 3.0, 1.5 + (s[:, 1] - 0.5) * 2.0
    z = 6.0 + (0.8 * (x * x + 0.5 * y * y) * rng.choice([-1, 1]) if curved else 0.3 * x)
    return np.stack([x, y, z], axis=1) + rng.normal(0, 0.02, (len(s), 3))


def directions(rng, p, mode):
    if mode == "diverging":  # from an eye behind the base, unit length
        d = p - np.array([0.0, 2.5, 9.0])
        return d / np.linalg.norm(d, axis=1, keepdims=True)
    if mode == "converging":  # through a point in front of the scene: rays cross there
        return np.array([0.0, 1.8, 3.8]) - p
    if mode == "crossing":  # random unit directions around -z, neighbours cross
        d = np.array([0.0, -0.35, -1.0]) + rng.normal(0, 0.35, p.shape)
        return d / np.linalg.norm(d, axis=1, keepdims=True)
    if mode == "unequal":  # diverging, lengths 0.3 to 3 times
        return (p - np.array([0.0, 2.5, 9.0])) * rng.uniform(0.3, 3.0, (len(p), 1))
    raise ValueError(mode)


def toml_scene(title, w, h, proj, models) -> str:
    arr = lambda a: "[" + ", ".join("[" + ", ".join(f"{x:.9g}" for x in r) + "]" for r in a) + "]"
    return (f"# {title}\n[image]\nwidth = {w}\nheight = {h}\nbackground = [0.05, 0.05, 0.08]\n\n"
            f"[projection]\ntype = \"trilinear\"\npoints = {arr(proj[0])}\nnormals = {arr(proj[1])}\n"
            f"screen = {arr(proj[2])}\ntriangles = {arr(proj[3])}\n" + OBJECTS.replace("{models}", models))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out", type=Path)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--models", type=Path, default=Path("scenes/models"))
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)
    out = args.out
    out.mkdir(parents=True, exist_ok=True)
    (out / "sphere.obj").write_text(uv_sphere())
    models = str(args.models.resolve())
    grids = [(1, 1, 1.0), (2, 2, 0.8), (3, 4, 0.85), (5, 5, 0.9)]
    for n, (nx, ny, keep) in enumerate(grids):
        for curved in (False, True):
            for mode in ("diverging", "converging", "crossing", "unequal"):
                s, tris = grid_mesh(rng, nx, ny, keep)
                p = base_points(rng, s, curved)
                d = directions(rng, p, mode)
                name = f"rand{n}-{len(tris):02d}-{'curved' if curved else 'planar'}-{mode}"
                w, h = int(rng.integers(120, 260)), int(rng.integers(90, 200))
                (out / f"{name}.toml").write_text(toml_scene(name, w, h, (p, d, s, tris), models))
    # Rays that start inside the scene: a base plane through the cube and the floor.
    s, tris = grid_mesh(rng, 3, 3, 1.0)
    p = np.stack([(s[:, 0] - 0.5) * 3.0, 0.3 + s[:, 1] * 2.0, 0.2 + 0.1 * s[:, 0]], axis=1)
    d = np.array([0.0, -0.2, -1.0]) + rng.normal(0, 0.15, p.shape)
    (out / "inside-cube.toml").write_text(toml_scene("base through the cube", 240, 180, (p, d, s, tris), models))
    # Pinhole: every base point at the eye (a collapsed base), perspective-like directions.
    s, tris = grid_mesh(rng, 4, 3, 1.0)
    p = np.tile([0.0, 4.0, 7.5], (len(s), 1))
    d = np.stack([(s[:, 0] - 0.5) * 1.6, -0.7 + (s[:, 1] - 0.5) * 1.2, -np.ones(len(s))], axis=1)
    (out / "pinhole.toml").write_text(toml_scene("pinhole: collapsed base", 240, 180, (p, d, s, tris), models))


if __name__ == "__main__":
    main()
