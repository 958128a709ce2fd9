"""Cross-check flexcam's projection presets against Blender Cycles' cameras, pixel by pixel.

For every seed: a random scene of triangle meshes around a random camera (scene.py), written
as OBJ files. For every case (cases.py): Cycles renders an id image through its camera
(blender_side.py), flexcam renders `--ids` through the equivalent projection with
`--method raycast` and `--method raster`, and the id images are compared: the fraction of
pixels with the same id over the whole image, and over the pixels not within 1 px of an id
edge (pixels whose 3 x 3 neighbourhood holds one id in both images). Difference images
(grey: agree, red: disagree) go next to the renders.

Run with the Python that has `bpy` (see README.md):
    /work/venv-bpy/bin/python tools/crosscheck/blender/crosscheck.py --seeds 1,2,3
"""

import argparse
import math
import os
import subprocess
import sys

import numpy as np
from PIL import Image

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import blender_side  # noqa: E402
import cases  # noqa: E402
import closed_form  # noqa: E402
import scene  # noqa: E402

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))


def camera_frame(seed):
    """A random eye and a view direction within 30 degrees of horizontal (y up)."""
    rng = np.random.default_rng(seed + 1000)
    eye = [float(x) for x in rng.uniform(-3, 3, 3)]
    azimuth = rng.uniform(0, 2 * math.pi)
    elevation = math.radians(rng.uniform(-30, 30))
    fwd = [math.cos(elevation) * math.sin(azimuth), math.sin(elevation),
           math.cos(elevation) * math.cos(azimuth)]
    look_at = [eye[i] + 5 * fwd[i] for i in range(3)]
    up_world = np.array([0.0, 1.0, 0.0])
    f = np.array(fwd)
    right = np.cross(f, up_world)
    right /= np.linalg.norm(right)
    up = np.cross(right, f)
    return {"eye": eye, "look_at": look_at, "forward": fwd, "up": [float(x) for x in up]}


def flexcam_scene(path, frame, width, height, projection_keys, obj_names):
    with open(path, "w") as f:
        f.write(f"[image]\nwidth = {width}\nheight = {height}\nbackground = [0.0, 0.0, 0.0]\n\n")
        f.write('[projection]\ntype = "flexible"\n')
        if "preset" in projection_keys:
            f.write(cases.keys(position=frame["eye"], look_at=frame["look_at"], up=[0, 1, 0]))
        f.write(projection_keys)
        for name in obj_names:
            f.write(f'\n[[object]]\nshape = "mesh"\nfile = "obj/{name}"\n')


def flexcam_ids(binary, scene_path, method, out_png):
    """Renders flexcam's id image; returns (ids array or None, error line)."""
    cmd = [binary, "render", scene_path, "--method", method, "--shading", "flat",
           "--ids", out_png, "-o", out_png.replace(".png", "-color.png")]
    run = subprocess.run(cmd, capture_output=True, text=True)
    if run.returncode != 0:
        return None, (run.stderr.strip().splitlines() or ["(no message)"])[-1]
    return np.array(Image.open(out_png)).astype(np.int64), ""


def interior(ids):
    """Pixels whose 3 x 3 neighbourhood (clipped at the border) holds a single id."""
    h, w = ids.shape
    pad = np.pad(ids, 1, mode="edge")
    same = np.ones((h, w), dtype=bool)
    for dy in (0, 1, 2):
        for dx in (0, 1, 2):
            same &= pad[dy:dy + h, dx:dx + w] == ids
    return same


def compare(ref, other, diff_png):
    agree = ref == other
    inner = interior(ref) & interior(other)
    rgb = np.zeros(ref.shape + (3,), dtype=np.uint8)
    rgb[agree] = (128, 128, 128)
    rgb[~agree] = (255, 0, 0)
    Image.fromarray(rgb).save(diff_png)
    n_inner = int(inner.sum())
    return {
        "all": float(agree.mean()),
        "interior": float(agree[inner].mean()) if n_inner else float("nan"),
        "interior_px": n_inner,
        "mismatch_interior": int((~agree & inner).sum()),
        "mismatch": int((~agree).sum()),
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--flexcam", default=os.path.join(REPO, "target", "release", "flexcam"))
    ap.add_argument("--out", default="/tmp/flexcam-blender")
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--cases", default="all", help="comma-separated case names, or all")
    ap.add_argument("--objects", type=int, default=40)
    ap.add_argument("--controls", action="store_true",
                    help="add negative controls: flexcam parameters slightly off, which "
                    "must disagree (shows the comparison can fail)")
    ap.add_argument("--explain", action="store_true",
                    help="judge every mismatched raycast pixel by its closed-form ray in "
                    "double precision: whose id is right, and is an edge within Cycles' "
                    "sample spread (0.005 px)")
    args = ap.parse_args()
    seeds = [int(s) for s in args.seeds.split(",")]
    chosen = cases.all_cases() + (cases.controls() if args.controls else [])
    if args.cases != "all":
        wanted = set(args.cases.split(","))
        chosen = [c for c in chosen if c[0] in wanted]
        if not chosen:
            sys.exit(f"no case named {args.cases}")
    results = []
    for seed in seeds:
        frame = camera_frame(seed)
        folder = os.path.join(args.out, f"seed{seed}")
        objects = scene.random_scene(seed, frame["eye"], frame["forward"], args.objects)
        names = scene.write_objs(objects, os.path.join(folder, "obj"))
        tris, tri_ids = closed_form.load_triangles(objects)
        for name, btext, ftext, width, height, setup, fkeys in chosen:
            blender_side.reset()
            blender_side.import_objects(os.path.join(folder, "obj"), names)
            cam = blender_side.place_camera(frame["eye"], frame["look_at"], [0, 1, 0])
            setup(cam, frame)
            ref = blender_side.render_ids(width, height, os.path.join(folder, f"{name}-cycles.exr"))
            scene_path = os.path.join(folder, f"{name}.toml")
            flexcam_scene(scene_path, frame, width, height, fkeys(frame), names)
            row = {"seed": seed, "case": name, "blender": btext, "flexcam": ftext,
                   "size": f"{width}x{height}", "bad_cycles_px": int((ref < 0).sum()),
                   "objects_seen": len(set(np.unique(ref)) - {0, -1})}
            for method in ("raycast", "raster"):
                png = os.path.join(folder, f"{name}-{method}.png")
                ids, err = flexcam_ids(args.flexcam, scene_path, method, png)
                if ids is None:
                    row[method] = {"error": err}
                    continue
                row[method] = compare(ref, ids, os.path.join(folder, f"{name}-{method}-diff.png"))
                if args.explain and method == "raycast":
                    row["explained"] = closed_form.explain(name, frame, tris, tri_ids, ref, ids)
            results.append(row)
            print(format_row(row), flush=True)
    print()
    print(summary(results))


def _cell(r):
    if "error" in r:
        return "refused"
    return (f"{100 * r['all']:.2f} / {100 * r['interior']:.3f} "
            f"({r['mismatch']} / {r['mismatch_interior']})")


def format_row(row):
    return (f"seed {row['seed']} {row['case']:26s} objects {row['objects_seen']:2d} "
            f"raycast {_cell(row['raycast'])}  raster {_cell(row['raster'])}"
            + (f"  non-id Cycles px {row['bad_cycles_px']}" if row["bad_cycles_px"] else "")
            + ("" if "error" not in row["raster"] else f"  [{row['raster']['error']}]")
            + ("" if not row.get("explained") else
               "  closed form: {} mismatched, flexcam right {}, Cycles right {}, "
               "edge within 0.005 px {}".format(*row["explained"])))


def summary(results):
    """A Markdown table, one row per case: the worst seed's numbers."""
    lines = ["| Cycles camera | flexcam | size | raycast: all / interior % (mismatched "
             "pixels: all / interior), worst seed | raster: same |", "| --- | --- | --- | --- | --- |"]
    for case in dict.fromkeys(r["case"] for r in results):
        rows = [r for r in results if r["case"] == case]

        def worst(method):
            ok = [r[method] for r in rows if "error" not in r[method]]
            if not ok:
                return "refused"
            return _cell(min(ok, key=lambda m: (m["interior"], m["all"])))

        r0 = rows[0]
        lines.append(f"| {r0['blender']} | {r0['flexcam']} | {r0['size']} | "
                     f"{worst('raycast')} | {worst('raster')} |")
    return "\n".join(lines)


if __name__ == "__main__":
    main()
