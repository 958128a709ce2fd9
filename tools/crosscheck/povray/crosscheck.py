#!/usr/bin/env python3
"""Cross-check flexcam's trilinear renders against POV-Ray 3.7's mesh_camera, by object ids.

    crosscheck.py SCENE.toml [--flexcam target/release/flexcam] [--out DIR] [--subdiv 16]
                  [--base-shift 1e-4] [--json FILE]

Renders SCENE with `flexcam render --ids` (methods raycast and trilinear) and, from this tool's
own reading of the scene file, with POV-Ray; prints the agreement of each pair. A scene with a
standard projection (perspective, orthographic, fisheye, equirectangular, cylindrical) is
compared with the matching POV-Ray camera and `--method raycast` only. See README.md.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import png

import flexscene
import povwrite
from compare import compare


def read_png(path: Path) -> np.ndarray:
    with open(path, "rb") as f:
        w, h, rows, info = png.Reader(file=f).asDirect()
        a = np.vstack([np.asarray(r, dtype=np.int64) for r in rows])
    return a.reshape(h, w, info["planes"])


def render_pov(scene: flexscene.Scene, out: Path, subdiv: int, base_shift: float) -> tuple[np.ndarray, dict]:
    source, info = povwrite.scene_source(scene, subdiv, base_shift)
    pov, image = out / "scene.pov", out / "povray.png"
    pov.write_text(source)
    w, h = scene.width, scene.height
    pad = 1 if info["padded"] else 0
    cmd = ["povray", f"+I{pov}", f"+O{image}", f"+W{w + pad}", f"+H{h + pad}", "-A", "-J", "-D",
           "+FN16", "File_Gamma=1.0", "-V", "-GA"]
    run = subprocess.run(cmd, capture_output=True, text=True)
    if run.returncode != 0 or not image.exists():
        raise RuntimeError(f"povray failed on {pov}: {run.stderr.strip().splitlines()[-3:]}")
    rgb = read_png(image)
    return povwrite.decode_ids(rgb[pad:, :w, 0]), info


def render_flexcam(flexcam: str, scene: Path, out: Path, method: str, w: int, h: int) -> np.ndarray:
    ids = out / f"{method}-ids.png"
    cmd = [flexcam, "render", str(scene), "--method", method, "--shading", "flat",
           "--width", str(w), "--height", str(h), "-o", str(out / f"{method}.png"), "--ids", str(ids)]
    run = subprocess.run(cmd, capture_output=True, text=True)
    if run.returncode != 0:
        raise RuntimeError(f"flexcam --method {method} failed: {run.stderr.strip()}")
    return read_png(ids)[..., 0]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    ap.add_argument("scene", type=Path)
    ap.add_argument("--flexcam", default="target/release/flexcam")
    ap.add_argument("--out", type=Path, default=Path("crosscheck-out"))
    ap.add_argument("--subdiv", type=int, default=16,
                    help="pieces per edge for triangles whose corner directions differ in length")
    ap.add_argument("--base-shift", type=float, default=1e-4,
                    help="ray parameter by which a collapsed (pinhole) base is moved along its rays")
    ap.add_argument("--json", type=Path)
    args = ap.parse_args()
    try:
        scene = flexscene.load(args.scene)
    except flexscene.SceneError as e:
        print(f"crosscheck: {e}", file=sys.stderr)
        return 2
    except (ValueError, KeyError, IndexError, TypeError) as e:
        # Malformed values inside the scene or a file it names (a bad number, a missing key).
        print(f"crosscheck: {args.scene} (or a file it names): {type(e).__name__}: {e}", file=sys.stderr)
        return 2
    for skipped in scene.skipped:
        flexscene.warn(f"{args.scene}: skipped {skipped}: not a plane, box, OBJ or ASCII PLY mesh")
    args.out.mkdir(parents=True, exist_ok=True)
    trilinear = not isinstance(scene.projection, dict)
    try:
        pov, info = render_pov(scene, args.out, args.subdiv, args.base_shift)
        ray = render_flexcam(args.flexcam, args.scene, args.out, "raycast", scene.width, scene.height)
        if trilinear:
            tri = render_flexcam(args.flexcam, args.scene, args.out, "trilinear", scene.width, scene.height)
    except (RuntimeError, OSError, ValueError) as e:
        print(f"crosscheck: {e}", file=sys.stderr)
        return 1
    result = {"scene": str(args.scene), "width": scene.width, "height": scene.height,
              "skipped": scene.skipped, "pov_camera": info, "povray_vs_raycast": compare(pov, ray)}
    if trilinear:
        result["povray_vs_trilinear"] = compare(pov, tri)
        result["raycast_vs_trilinear"] = compare(ray, tri)
    print(f"{args.scene} {scene.width}x{scene.height} camera {info}")
    for pair in [k for k in result if "_vs_" in k]:
        r = result[pair]
        print(f"  {pair:22s} all {100 * r['agree_all']:8.4f} % ({r['differ_all']} px)  "
              f"off-edge {100 * r['agree_interior']:8.4f} % ({r['differ_interior']} px, {r['regions']} regions)")
        for reg in r["largest_regions"][:3]:
            print(f"      region {reg['pixels']} px x {reg['x']} y {reg['y']} ids {reg['ids']}")
    if args.json:
        args.json.write_text(json.dumps(result, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
