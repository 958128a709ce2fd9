"""Writes a POV-Ray 3.7 scene whose image is an exact object-id map of a flexcam trilinear scene.

The camera is a `mesh_camera` with distribution type 3 (the image is mapped through the mesh's
uv coordinates; type 2 is side-by-side face-per-pixel cameras) and `smooth` (the ray direction
is interpolated from the vertex normals). Measured conventions of POV-Ray 3.7.0.10 (README.md):

- pixel (i, j) of a W x H render samples uv (i / W, 1 - j / H): the pixel's top-left corner,
  not its centre; the first row and the last column are clamped (v = 1 - 0.5 / H, u = (W - 1.5) / W).
  So the scene is rendered at (W + 1) x (H + 1) with uv = ((s W - 0.5) / (W + 1),
  1 - ((1 - t) H + 0.5) / (H + 1)) and cropped to rows 1..H, columns 0..W-1: then POV pixel
  (i, j + 1) samples flexcam's pixel centre (s, t) = ((i + 0.5) / W, 1 - (j + 0.5) / H) exactly.
- the ray starts at the base point and runs along +normal (camera `location` z would offset the
  origin along the ray, `direction` z < 0 would reverse it: both left at 0 and +1);
- vertex normals are normalised before interpolation, flexcam's trinorm is not: a triangle
  whose corner directions differ in length is subdivided (k x k) so that POV's rays match
  flexcam's at the sub-vertices (approximate inside, error O(1/k^2));
- a pixel in no uv triangle shoots no ray and comes out 0 (black), whatever the background.
Object id k is the emitted colour rgb <16 k / 65535, 0, 0>, read back from a 16-bit PNG
(+FN16, File_Gamma 1.0, assumed_gamma 1.0, no lights, no antialiasing).
"""

from __future__ import annotations

import numpy as np

import povcameras
from flexscene import Scene, Trilinear

ID_STEP = 16  # 16-bit levels between consecutive ids: ids up to 4095 survive any rounding


def camera_mesh(proj: Trilinear, subdiv: int, base_shift: float):
    """World-space (points, normals, screen) per POV corner, as (m, 3, ...) arrays.

    Triangles with unequal corner direction lengths are cut into subdiv x subdiv pieces.
    A triangle whose base points are (nearly) collinear (a pinhole: all at the eye) moves each
    corner to p + base_shift * n, which keeps every ray on its line (base and direction are
    both linear in the barycentrics) and only starts it base_shift later.
    Returns the arrays and the counts (subdivided, shifted).
    """
    out_p, out_n, out_s = [], [], []
    n_sub = n_shift = 0
    for tri in proj.triangles:
        p, n, s = proj.points[tri], proj.normals[tri], proj.screen[tri]
        area = np.linalg.norm(np.cross(p[1] - p[0], p[2] - p[0]))
        scale = max(np.ptp(p, axis=0).max(), np.linalg.norm(n, axis=1).max(), 1e-300)
        if area < 1e-9 * scale * scale:
            p = p + base_shift * n
            n_shift += 1
        # Equal up to 1e-5: OBJ files carry about six digits (unit normals written as text).
        lengths = np.linalg.norm(n, axis=1)
        k = subdiv if np.ptp(lengths) > 1e-5 * lengths.max() else 1
        n_sub += k > 1
        for bary in _sub_triangles(k):
            out_p.append(bary @ p), out_n.append(bary @ n), out_s.append(bary @ s)
    return np.array(out_p), np.array(out_n), np.array(out_s), n_sub, n_shift


def _sub_triangles(k: int):
    """Barycentric (3 x 3) corner weights of the k x k sub-triangles of a triangle."""
    def b(i, j):
        return np.array([(k - i - j) / k, i / k, j / k])

    for i in range(k):
        for j in range(k - i):
            yield np.array([b(i, j), b(i + 1, j), b(i, j + 1)])
            if i + j + 1 < k:
                yield np.array([b(i + 1, j), b(i + 1, j + 1), b(i, j + 1)])


def pov_uv(screen: np.ndarray, width: int, height: int) -> np.ndarray:
    """flexcam screen (s, t) -> the uv that a (W + 1) x (H + 1) POV render samples there."""
    u = (screen[..., 0] * width - 0.5) / (width + 1)
    v = 1.0 - ((1.0 - screen[..., 1]) * height + 0.5) / (height + 1)
    return np.stack([u, v], axis=-1)


def scene_source(scene: Scene, subdiv: int, base_shift: float) -> tuple[str, dict]:
    """The POV-Ray scene and facts about its camera. A trilinear projection becomes a mesh
    camera (rendered one pixel larger each way, see the module doc); any other projection the
    equivalent POV-Ray camera of povcameras.py (ValueError if there is none)."""
    lines = [
        "#version 3.7;",
        "global_settings { assumed_gamma 1.0 ambient_light 0 max_trace_level 1 }",
        "background { rgb 0 }",
    ]
    if isinstance(scene.projection, dict):
        cam = povcameras.camera(scene.projection, scene.width, scene.height)
        if cam is None:
            raise ValueError(f"no POV-Ray camera for projection type {scene.projection.get('type')!r}")
        lines.append(cam)
        info = {"camera": scene.projection.get("type"), "padded": False}
    else:
        info = _mesh_camera(lines, scene, subdiv, base_shift)
    _objects(lines, scene)
    return "\n".join(lines) + "\n", info


def _mesh_camera(lines: list[str], scene: Scene, subdiv: int, base_shift: float) -> dict:
    p, n, s, n_sub, n_shift = camera_mesh(scene.projection, subdiv, base_shift)
    uv = pov_uv(s, scene.width, scene.height)
    m = len(p)
    lines += [
        "#declare CamMesh = mesh2 {",
        _vectors("vertex_vectors", p.reshape(-1, 3)),
        _vectors("normal_vectors", n.reshape(-1, 3)),
        _vectors("uv_vectors", uv.reshape(-1, 2)),
        _indices("face_indices", m),
        _indices("normal_indices", m),
        _indices("uv_indices", m),
        "}",
        "camera { mesh_camera { 1 3 mesh { CamMesh } smooth } location <0, 0, 0> direction <0, 0, 1> }",
    ]
    return {"camera": "mesh", "padded": True, "camera_triangles": m, "subdivided": n_sub, "shifted": n_shift}


def _objects(lines: list[str], scene: Scene) -> None:
    for oid, name, tris in scene.objects:
        lines += [
            f"// object {oid}: {name}",
            "mesh2 {",
            _vectors("vertex_vectors", tris.reshape(-1, 3)),
            _indices("face_indices", len(tris)),
            f"  pigment {{ rgb <{oid * ID_STEP / 65535.0:.17g}, 0, 0> }}",
            "  finish { ambient 0 diffuse 0 specular 0 phong 0 emission 1 }",
            "}",
        ]


def decode_ids(red16: np.ndarray) -> np.ndarray:
    return np.rint(red16 / ID_STEP).astype(np.int64)


def _vectors(key: str, rows: np.ndarray) -> str:
    body = ",\n".join("<" + ", ".join(f"{x:.17g}" for x in r) + ">" for r in rows)
    return f"  {key} {{ {len(rows)},\n{body} }}"


def _indices(key: str, m: int) -> str:
    body = ", ".join(f"<{3 * i}, {3 * i + 1}, {3 * i + 2}>" for i in range(m))
    return f"  {key} {{ {m}, {body} }}"
