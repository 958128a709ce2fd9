#!/usr/bin/env python3
"""Writes a fit scene for timing `flexcam fit`: N correspondences picked (`flexcam pick`) at
random image positions of a 320 x 240 perspective view of a floor and a box (eye at
[1, 4.5, 8], not the prior's), their positions jittered by 1.5 px of Gaussian noise, fitted
by a GRID x GRID bilinear grid with the given `starts` from a 60-degree perspective prior
whose eye is elsewhere ([0, 5.5, 7]).

usage: make-speed-case.py FLEXCAM N GRID STARTS OUT.toml   (seed 7: the same file each run)
"""
import json
import os
import random
import subprocess
import sys
import tempfile

OBJECTS = """
[[object]]
name = "floor"
shape = "plane"
size = [8.0, 8.0]
color = [0.9, 0.9, 0.9]

[[object]]
name = "box"
shape = "box"
size = [2.0, 2.0, 2.0]
translate = [0.0, 1.0, 0.0]
color = [0.8, 0.2, 0.2]
"""

TRUTH = """[image]
width = 320
height = 240

[projection]
type = "perspective"
position = [1.0, 4.5, 8.0]
look_at = [0.0, 0.5, 0.0]
fov = 55.0
""" + OBJECTS


def main():
    flexcam, n, grid, starts, out = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4], sys.argv[5]
    random.seed(7)
    with tempfile.TemporaryDirectory() as tmp:
        truth = os.path.join(tmp, "truth.toml")
        with open(truth, "w") as f:
            f.write(TRUTH)
        # Inside a 4 px margin, so that the noise keeps every position in the image.
        pixels = [(random.uniform(4, 316), random.uniform(4, 236)) for _ in range(3 * n)]
        picked = subprocess.run(
            [flexcam, "pick", truth, "--json"] + [f"{x:.3f},{y:.3f}" for x, y in pixels],
            capture_output=True, text=True, check=True)
    rows = [json.loads(line) for line in picked.stdout.splitlines() if line.strip()]
    rows = [r for r in rows if r.get("object")][:n]
    if len(rows) < n:
        sys.exit(f"only {len(rows)} of {n} positions see an object")
    entries = []
    for r in rows:
        x, y = r["pixel"]
        x += random.gauss(0, 1.5)
        y += random.gauss(0, 1.5)
        p = r["point"]
        entries.append(f"  {{ uv = [{x / 320:.6f}, {1 - y / 240:.6f}], "
                       f"point = [{p[0]:.6f}, {p[1]:.6f}, {p[2]:.6f}] }},")
    scene = f"""[image]
width = 320
height = 240

[projection]
type = "flexible"
preset = "perspective"
position = [0.0, 5.5, 7.0]
look_at = [0.0, 0.4, 0.0]
fov = 60.0
clip = [0.5, 40.0]

[projection.projectors]
size = [{grid}, {grid}]
interpolation = "bilinear"
starts = "{starts}"
fit = [
""" + "\n".join(entries) + "\n]\n" + OBJECTS
    with open(out, "w") as f:
        f.write(scene)


if __name__ == "__main__":
    main()
