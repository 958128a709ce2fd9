"""Unit tests of the crosscheck tool itself (python3 -m unittest, from this folder)."""

import shutil
import tempfile
import unittest
from pathlib import Path

import numpy as np

import compare
import crosscheck
import flexscene
import povwrite
import ray_at
from flexscene import Trilinear


class PovMapping(unittest.TestCase):
    def test_pixel_centres_map_to_the_uv_povray_samples(self):
        # POV pixel (i, j') of a (W+1) x (H+1) render samples uv (i / (W+1), 1 - j' / (H+1)).
        w, h = 7, 5
        for i in range(w):
            for j in range(h):
                s, t = (i + 0.5) / w, 1 - (j + 0.5) / h
                u, v = povwrite.pov_uv(np.array([s, t]), w, h)
                self.assertAlmostEqual(u, i / (w + 1), places=12)
                self.assertAlmostEqual(v, 1 - (j + 1) / (h + 1), places=12)

    def test_subdivision_tiles_the_triangle(self):
        for k in (1, 2, 5):
            pieces = list(povwrite._sub_triangles(k))
            self.assertEqual(len(pieces), k * k)
            area = sum(abs(np.linalg.det(np.c_[b[:, 1:], np.ones(3)])) / 2 for b in pieces)
            self.assertAlmostEqual(area, 0.5)

    def test_unequal_lengths_are_subdivided_and_a_pinhole_is_shifted_along_its_rays(self):
        pts = np.zeros((3, 3))
        nrm = np.array([[-1.0, -1, -1], [1, -1, -1], [0, 1, -1]])
        proj = Trilinear(pts, nrm, np.array([[0, 0], [1, 0], [0, 1.0]]), np.array([[0, 1, 2]]))
        p, n, s, n_sub, n_shift = povwrite.camera_mesh(proj, 4, 0.5)
        self.assertEqual((n_sub, n_shift, len(p)), (1, 1, 16))
        # Every POV corner lies on the spec's ray through it: p = 0 + 0.5 * n.
        self.assertTrue(np.allclose(p, 0.5 * n))

    @unittest.skipUnless(shutil.which("povray"), "povray is not installed")
    def test_povray_ids_match_the_spec_rays_pixel_by_pixel(self):
        # A 2-triangle projection with unit, crossing directions over a box on a plane: every
        # pixel of POV-Ray's id image equals the brute-force spec ray's first hit (ray_at.py).
        rng = np.random.default_rng(7)
        pts = np.array([[-1.5, 0.5, 5.0], [1.5, 0.6, 5.2], [1.4, 2.5, 5.1], [-1.6, 2.4, 4.9]])
        nrm = np.array([0.0, -0.4, -1.0]) + rng.normal(0, 0.2, (4, 3))
        nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
        screen = np.array([[0, 0], [1, 0], [1, 1], [0, 1.0]])
        proj = Trilinear(pts, nrm, screen, np.array([[0, 1, 2], [0, 2, 3]]))
        box = flexscene._object_triangles(None, {"shape": "box", "size": [1.5, 1.5, 1.5]})
        plane = flexscene._object_triangles(None, {"shape": "plane", "size": [6.0, 6.0]})
        scene = flexscene.Scene(31, 23, proj, [(1, "plane", plane), (2, "box", box + [0, 0.75, 0])])
        with tempfile.TemporaryDirectory() as out:
            pov, _ = crosscheck.render_pov(scene, Path(out), 16, 1e-4)
        expect = np.zeros_like(pov)
        for y in range(scene.height):
            for x in range(scene.width):
                o, d, _, _ = ray_at.pixel_ray(proj, (x + 0.5) / 31, 1 - (y + 0.5) / 23)
                expect[y, x] = ray_at.first_hit(scene, o, d)[1]
        self.assertTrue({1, 2} <= set(np.unique(expect).tolist()))
        self.assertTrue((pov == expect).all(), np.argwhere(pov != expect))


class Compare(unittest.TestCase):
    def test_edge_pixels_are_excluded_and_regions_found(self):
        a = np.zeros((10, 10), int)
        a[:, 5:] = 1
        b = a.copy()
        b[0, 4] = 1  # on the edge
        b[7:9, 1:3] = 2  # inside
        r = compare.compare(a, b)
        self.assertEqual(r["differ_all"], 5)
        self.assertEqual(r["differ_interior"], 0)  # the 2x2 block is its own edge in b
        b[6:10, 0:4] = 2
        r = compare.compare(a, b)
        self.assertEqual(r["regions"], 1)
        self.assertGreater(r["differ_interior"], 0)


if __name__ == "__main__":
    unittest.main()
