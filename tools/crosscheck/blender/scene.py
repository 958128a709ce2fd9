"""Random test scenes for the Blender cross-check: triangle meshes placed around a camera.

Every object is a list of triangles in flexcam's world (right-handed, y up). The same
triangles are written as one OBJ file per object (flexcam reads them as `shape = "mesh"`
objects, ids 1, 2, ... in file order) and imported into Blender, so both renderers see
exactly the same geometry.
"""

import math
import os
import random


def _unit(v):
    n = math.sqrt(sum(c * c for c in v))
    return [c / n for c in v]


def _random_rotation(rng):
    """A random rotation matrix (rows), from a random unit quaternion."""
    q = _unit([rng.gauss(0, 1) for _ in range(4)])
    w, x, y, z = q
    return [
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ]


def _apply(rot, centre, p):
    return [centre[i] + sum(rot[i][j] * p[j] for j in range(3)) for i in range(3)]


def _box(size):
    hx, hy, hz = (0.5 * s for s in size)
    corners = [[sx * hx, sy * hy, sz * hz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]
    # Faces as quads of corner indices (index = 4 sx + 2 sy + sz with s in {0, 1}).
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    tris = []
    for a, b, c, d in quads:
        tris.append([corners[a], corners[b], corners[c]])
        tris.append([corners[a], corners[c], corners[d]])
    return tris


def _sphere(radius, stacks=10, slices=20):
    def point(i, j):
        lat = math.pi * (i / stacks - 0.5)
        lon = 2 * math.pi * j / slices
        return [radius * math.cos(lat) * math.cos(lon), radius * math.sin(lat),
                radius * math.cos(lat) * math.sin(lon)]

    tris = []
    for i in range(stacks):
        for j in range(slices):
            a, b = point(i, j), point(i, j + 1)
            c, d = point(i + 1, j + 1), point(i + 1, j)
            if i > 0:
                tris.append([a, b, c])
            if i < stacks - 1:
                tris.append([a, c, d])
    return tris


def _triangle(rng, size):
    return [[[rng.uniform(-size, size) for _ in range(3)] for _ in range(3)]]


def random_scene(seed, eye, forward, count=40):
    """`count` objects around `eye`: half anywhere around it (for the panoramas), half
    within about 35 degrees of `forward` (so the narrow views see several objects), at
    distances 2 to 12. Returns a list of (kind, triangles)."""
    rng = random.Random(seed)
    forward = _unit(forward)
    objects = []
    for k in range(count):
        while True:
            d = _unit([rng.gauss(0, 1) for _ in range(3)])
            if k % 2 == 0 or sum(a * b for a, b in zip(d, forward)) > math.cos(math.radians(35)):
                break
        dist = rng.uniform(2.0, 12.0)
        centre = [eye[i] + dist * d[i] for i in range(3)]
        kind = rng.choice(["box", "sphere", "triangle"])
        scale = 0.12 * dist
        if kind == "box":
            local = _box([rng.uniform(0.3, 1.5) * scale for _ in range(3)])
        elif kind == "sphere":
            local = _sphere(rng.uniform(0.3, 0.8) * scale)
        else:
            local = _triangle(rng, 1.2 * scale)
        rot = _random_rotation(rng)
        objects.append((kind, [[_apply(rot, centre, p) for p in t] for t in local]))
    return objects


def write_objs(objects, folder):
    """One OBJ per object, `obj_001.obj`, ...; returns the file names in id order."""
    os.makedirs(folder, exist_ok=True)
    names = []
    for i, (_, tris) in enumerate(objects, start=1):
        name = f"obj_{i:03d}.obj"
        with open(os.path.join(folder, name), "w") as f:
            f.write(f"o object_{i}\n")
            for t in tris:
                for p in t:
                    f.write("v {:.9g} {:.9g} {:.9g}\n".format(*p))
            for k in range(len(tris)):
                f.write(f"f {3 * k + 1} {3 * k + 2} {3 * k + 3}\n")
        names.append(name)
    return names
