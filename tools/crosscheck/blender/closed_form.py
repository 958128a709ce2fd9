"""Single rays by hand: the closed form of each matching case's projection (the one both
renderers should implement), in double precision, to judge a mismatched pixel.

`RAYS[case](X, Y, W, H)` gives the ray of the continuous pixel position (X, Y) (x right,
y down, pixel centres at +0.5) of a W x H image as (origin, direction) in the camera's
local frame (x right, y up, z forward, eye at the origin), or None where the projection
has no ray. `explain` intersects such rays with every triangle of the scene.
"""

import math

import numpy as np

T35 = math.tan(math.radians(35.0))


def _uv(X, Y, W, H):
    return X / W, 1.0 - Y / H


def _perspective(shift=(0.0, 0.0)):
    def ray(X, Y, W, H):
        u, v = _uv(X, Y, W, H)
        return np.zeros(3), np.array([(2 * u - 1 + shift[0]) * T35,
                                      (2 * v - 1 + shift[1]) * T35 * H / W, 1.0])
    return ray


def _orthographic(width):
    def ray(X, Y, W, H):
        u, v = _uv(X, Y, W, H)
        half = 0.5 * width
        return np.array([(2 * u - 1) * half, (2 * v - 1) * half * H / W, 0.0]), np.array([0, 0, 1.0])
    return ray


def _equirect(lon, lat):
    def ray(X, Y, W, H):
        u, v = _uv(X, Y, W, H)
        lo = math.radians(lon[0] + u * (lon[1] - lon[0]))
        la = math.radians(lat[0] + v * (lat[1] - lat[0]))
        return np.zeros(3), np.array([math.cos(la) * math.sin(lo), math.sin(la),
                                      math.cos(la) * math.cos(lo)])
    return ray


def _fisheye(fov, angle_of_radius):
    """Polar maps: the circle inscribed in the shorter side, theta = angle_of_radius(r, half)."""
    half = math.radians(0.5 * fov)

    def ray(X, Y, W, H):
        R = 0.5 * min(W, H)
        px, py = (X - 0.5 * W) / R, (0.5 * H - Y) / R
        r = math.hypot(px, py)
        if r > 1.0:
            return None
        theta = angle_of_radius(r, half)
        s = math.sin(theta) / r if r > 0 else 0.0
        return np.zeros(3), np.array([s * px, s * py, math.cos(theta)])
    return ray


def _equidistant(r, half):
    return r * half


def _lens(r, half):
    return (0.25 * r + 0.75 * r * r) * half


def _equisolid(r, half):
    return 2.0 * math.asin(min(1.0, r * math.sin(0.5 * half)))


def _cylindrical(h_fov, v_fov):
    def ray(X, Y, W, H):
        u, v = _uv(X, Y, W, H)
        a = math.radians((u - 0.5) * h_fov)
        height = (2 * v - 1) * math.tan(math.radians(0.5 * v_fov))
        return np.zeros(3), np.array([math.sin(a), height, math.cos(a)])
    return ray


def _equiangular(fov):
    """Angles off the axis linear in x and y (the vertical half angle the pinhole's)."""
    half = math.radians(0.5 * fov)

    def ray(X, Y, W, H):
        u, v = _uv(X, Y, W, H)
        half_y = math.atan(math.tan(half) * H / W)
        return np.zeros(3), np.array([math.tan((2 * u - 1) * half),
                                      math.tan((2 * v - 1) * half_y), 1.0])
    return ray


RAYS = {
    "perspective": _perspective(),
    "off_axis": _perspective((0.2, -0.16 * 320 / 240)),
    "orthographic": _orthographic(6.0),
    "equirect_full": _equirect((-180, 180), (-90, 90)),
    "equirect_window": _equirect((-100, 100), (-50, 50)),
    "equirect_asym": _equirect((-120, 60), (-30, 70)),
    "fisheye_equidistant_180": _fisheye(180.0, _equidistant),
    "fisheye_equidistant_280": _fisheye(280.0, _equidistant),
    "polynomial_equidistant": _fisheye(200.0, _equidistant),
    "polynomial_lens": _fisheye(180.0, _lens),
    "fisheye_equisolid_180": _fisheye(180.0, _equisolid),
    "fisheye_equisolid_300": _fisheye(300.0, _equisolid),
    "mirror_ball": _fisheye(360.0, _equisolid),
    "equiangular_face": _equiangular(90.0),
    "central_cylindrical": _cylindrical(300.0, 100.0),
}

# Cycles' sample spread around the pixel centre (box filter of width 0.01 px).
JITTER = 0.005


def load_triangles(objects):
    """All triangles of `objects` (scene.random_scene's list) and their ids."""
    tris, ids = [], []
    for object_id, (_, object_tris) in enumerate(objects, start=1):
        tris.extend(object_tris)
        ids.extend([object_id] * len(object_tris))
    return np.array(tris, dtype=np.float64), np.array(ids)


def first_id(origin, direction, tris, ids):
    """The id of the nearest triangle hit at t > 0 (Moller-Trumbore), 0 for none."""
    a = tris[:, 0]
    e1, e2 = tris[:, 1] - a, tris[:, 2] - a
    p = np.cross(direction, e2)
    det = (e1 * p).sum(1)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = origin - a
        u = (s * p).sum(1) / det
        q = np.cross(s, e1)
        w = (q @ direction) / det
        t = (e2 * q).sum(1) / det
        hit = (u >= 0) & (w >= 0) & (u + w <= 1) & (t > 1e-9)
    if not hit.any():
        return 0
    return int(ids[hit][np.argmin(t[hit])])


def explain(case, frame, tris, ids, ref, got):
    """For each pixel where `got` (flexcam) and `ref` (Cycles) differ: the closed form's id
    at the pixel centre and whether moving the ray by JITTER px changes it. Returns
    (mismatches, flexcam equal to the closed form, Cycles equal to it, near an edge), or
    None when the case has no closed form here."""
    ray = RAYS.get(case)
    if ray is None:
        return None
    f, up = np.array(frame["forward"]), np.array(frame["up"])
    right = np.cross(f, up)
    eye = np.array(frame["eye"])
    h, w = ref.shape

    def id_at(X, Y):
        local = ray(X, Y, w, h)
        if local is None:
            return 0
        o, d = local
        world_o = eye + o[0] * right + o[1] * up + o[2] * f
        world_d = d[0] * right + d[1] * up + d[2] * f
        return first_id(world_o, world_d, tris, ids)

    counts = [0, 0, 0, 0]
    for y, x in zip(*np.nonzero(ref != got)):
        X, Y = x + 0.5, y + 0.5
        centre = id_at(X, Y)
        near = any(id_at(X + dx, Y + dy) != centre
                   for dx, dy in ((JITTER, 0), (-JITTER, 0), (0, JITTER), (0, -JITTER)))
        counts[0] += 1
        counts[1] += int(got[y, x] == centre)
        counts[2] += int(ref[y, x] == centre)
        counts[3] += int(near)
    return tuple(counts)
