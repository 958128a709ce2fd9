"""Reads a flexcam scene file (TOML) without flexcam: the trilinear projection mesh and the
scene objects as world-space triangle lists, each tagged with its object id (file order from 1).

Independent of flexcam's code on purpose: this is the second opinion. Only what the crosscheck
needs is read: `[image]`, a `trilinear` projection given as `surface = "x.obj"` or as inline
`points`/`normals`/`screen`/`triangles` (any other projection is kept as its TOML table), and objects of shape `plane`, `box` and `mesh` (OBJ or
ASCII PLY). Other shapes (sphere, cylinder, torus, teapot: tessellated by flexcam in its own way)
and other model formats are skipped with a message, since a different tessellation would show up
as disagreement at silhouettes; their pixels are reported, not compared blindly.
"""

from __future__ import annotations

import math
import sys
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np


class SceneError(Exception):
    """Bad or unsupported input, with the file name in the message."""


@dataclass
class Trilinear:
    """Projection triangles: per corner a base point, a ray direction and a screen (s, t)."""

    points: np.ndarray  # (n, 3)
    normals: np.ndarray  # (n, 3)
    screen: np.ndarray  # (n, 2)
    triangles: np.ndarray  # (m, 3) int: corner indices into the three arrays


@dataclass
class Scene:
    width: int
    height: int
    projection: Trilinear | dict  # a dict: a standard projection's TOML table (povcameras.py)
    objects: list[tuple[int, str, np.ndarray]] = field(default_factory=list)  # (id, name, (k,3,3))
    skipped: list[str] = field(default_factory=list)


def load(path: Path) -> Scene:
    try:
        raw = tomllib.loads(path.read_text())
    except (OSError, tomllib.TOMLDecodeError) as e:
        raise SceneError(f"{path}: {e}") from e
    image = raw.get("image", {})
    width, height = int(image.get("width", 800)), int(image.get("height", 600))
    proj = raw.get("projection", {})
    scene = Scene(width, height, _projection(path, proj) if proj.get("type") == "trilinear" else proj)
    for index, obj in enumerate(raw.get("object", []), start=1):
        name = obj.get("name", f"object {index}")
        tris = _object_triangles(path, obj)
        if tris is None:
            scene.skipped.append(f"{name} (shape {obj.get('shape')!r})")
            continue
        scene.objects.append((index, name, _transform(obj) (tris)))
    return scene


def _projection(path: Path, proj: dict) -> Trilinear:
    if "surface" in proj:
        return load_obj_surface(path.parent / proj["surface"])
    if "grid" in proj:
        raise SceneError(f"{path}: trilinear `grid` projections are not supported by this tool")
    try:
        return Trilinear(
            np.array(proj["points"], float),
            np.array(proj["normals"], float),
            np.array(proj["screen"], float),
            np.array(proj["triangles"], int),
        )
    except KeyError as e:
        raise SceneError(f"{path}: trilinear projection lacks {e}") from e


def load_obj_surface(path: Path) -> Trilinear:
    """OBJ with `f v/vt/vn` corners; polygons are split into fans from their first corner."""
    v, vt, vn, pts, nrm, scr, tris = [], [], [], [], [], [], []
    for line_no, line in enumerate(_read_lines(path), start=1):
        words = line.split()
        if not words:
            continue
        key, args = words[0], words[1:]
        if key == "v":
            v.append([float(a) for a in args[:3]])
        elif key == "vt":
            vt.append([float(a) for a in args[:2]])
        elif key == "vn":
            vn.append([float(a) for a in args[:3]])
        elif key == "f":
            corners = []
            for c in args:
                parts = c.split("/")
                if len(parts) != 3 or not all(parts):
                    raise SceneError(f"{path}:{line_no}: face corner {c!r} is not v/vt/vn")
                i, j, k = (_obj_index(int(p), n) for p, n in zip(parts, (len(v), len(vt), len(vn))))
                corners.append(len(pts))
                pts.append(v[i]), scr.append(vt[j]), nrm.append(vn[k])
            tris += [[corners[0], corners[q], corners[q + 1]] for q in range(1, len(corners) - 1)]
    if not tris:
        raise SceneError(f"{path}: no faces")
    return Trilinear(np.array(pts), np.array(nrm), np.array(scr), np.array(tris))


def _obj_index(i: int, count: int) -> int:
    return i - 1 if i > 0 else count + i


def _read_lines(path: Path) -> list[str]:
    try:
        return [l.split("#", 1)[0] for l in path.read_text().splitlines()]
    except OSError as e:
        raise SceneError(f"{path}: {e}") from e


def _object_triangles(path: Path, obj: dict) -> np.ndarray | None:
    shape = obj.get("shape")
    if shape == "plane":
        w, d = (abs(float(x)) for x in obj.get("size", [1.0, 1.0]))
        quad = [[-w / 2, 0, d / 2], [w / 2, 0, d / 2], [w / 2, 0, -d / 2], [-w / 2, 0, -d / 2]]
        return _fan(np.array(quad))
    if shape == "box":
        size = obj.get("size", [1.0, 1.0, 1.0])
        h = np.abs(np.array([size] * 3 if np.isscalar(size) else size, float)) / 2
        corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * h
        faces = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]]
        return np.concatenate([_fan(corners[f]) for f in faces])
    if shape == "mesh":
        file = path.parent / obj["file"]
        if file.suffix.lower() == ".obj":
            return _load_obj_mesh(file)
        if file.suffix.lower() == ".ply":
            return _load_ascii_ply(file)
    return None


def _fan(poly: np.ndarray) -> np.ndarray:
    return np.array([[poly[0], poly[q], poly[q + 1]] for q in range(1, len(poly) - 1)])


def _load_obj_mesh(path: Path) -> np.ndarray:
    v, tris = [], []
    for line in _read_lines(path):
        words = line.split()
        if words and words[0] == "v":
            v.append([float(a) for a in words[1:4]])
        elif words and words[0] == "f":
            idx = [_obj_index(int(w.split("/")[0]), len(v)) for w in words[1:]]
            tris.append(_fan(np.array([v[i] for i in idx])))
    return np.concatenate(tris)


def _load_ascii_ply(path: Path) -> np.ndarray:
    lines = [l.split() for l in path.read_text().splitlines()]
    if ["format", "ascii", "1.0"] not in lines:
        raise SceneError(f"{path}: only ASCII PLY is supported by this tool")
    counts, body = {}, lines.index(["end_header"]) + 1
    for words in lines[:body]:
        if words[:1] == ["element"]:
            counts[words[1]] = int(words[2])
    verts = np.array([[float(x) for x in w[:3]] for w in lines[body : body + counts["vertex"]]])
    faces = lines[body + counts["vertex"] : body + counts["vertex"] + counts["face"]]
    return np.concatenate([_fan(verts[[int(i) for i in w[1 : 1 + int(w[0])]]]) for w in faces])


def _transform(obj: dict):
    """flexcam's object transform T * Rz * Ry * Rx * S (degrees), as a function on (k,3,3)."""
    scale = obj.get("scale", 1.0)
    s = np.array([scale] * 3 if np.isscalar(scale) else scale, float)
    rx, ry, rz = (math.radians(a) for a in obj.get("rotate", [0, 0, 0]))
    c, n = math.cos, math.sin
    mx = np.array([[1, 0, 0], [0, c(rx), -n(rx)], [0, n(rx), c(rx)]])
    my = np.array([[c(ry), 0, n(ry)], [0, 1, 0], [-n(ry), 0, c(ry)]])
    mz = np.array([[c(rz), -n(rz), 0], [n(rz), c(rz), 0], [0, 0, 1]])
    m = mz @ my @ mx @ np.diag(s)
    t = np.array(obj.get("translate", [0, 0, 0]), float)
    return lambda tris: tris @ m.T + t


def warn(message: str) -> None:
    print(f"crosscheck: {message}", file=sys.stderr)
