"""The Blender (Cycles) side of the cross-check: import the OBJ files, give object k an
Emission shader of colour (k / 255, 0, 0), place the camera and render an id image.

Cycles settings chosen so that a pixel's value is exactly its object's id: Emission only
(no BSDF, so nothing is lit or reflected), a black world of strength 0, 1 sample per pixel,
box filter of the smallest width (0.01 px: the one sample sits at the pixel centre to
within 0.005 px), no denoising, no adaptive sampling, Standard view transform, and linear
32-bit float OpenEXR output (EXR is written scene-linear; no display transform).

Coordinates: flexcam's world is y up, Blender's z up. The OBJ importer is told the file is
y up / -z forward, so a file point (x, y, z) lands at Blender (x, -z, y); `to_blender`
is that map, used for the camera.
"""

import contextlib
import os
import sys

import bpy
import numpy as np
from mathutils import Matrix, Vector


@contextlib.contextmanager
def quiet():
    """Sends Blender's own progress lines (written to file descriptor 1) to /dev/null."""
    sys.stdout.flush()
    saved = os.dup(1)
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    try:
        yield
    finally:
        os.dup2(saved, 1)
        os.close(devnull)
        os.close(saved)


def to_blender(p):
    """flexcam world point or direction (y up) -> Blender world (z up)."""
    return Vector((p[0], -p[2], p[1]))


def reset():
    with quiet():
        bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    cy = scene.cycles
    cy.device = "CPU"
    cy.samples = 1
    cy.use_adaptive_sampling = False
    cy.use_denoising = False
    cy.pixel_filter_type = "BOX"
    cy.filter_width = 0.01
    cy.max_bounces = 0
    cy.seed = 0
    scene.render.threads_mode = "FIXED"
    scene.render.threads = 1
    scene.render.film_transparent = False
    scene.render.resolution_percentage = 100
    scene.render.pixel_aspect_x = 1.0
    scene.render.pixel_aspect_y = 1.0
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR"
    settings.color_depth = "32"
    settings.color_mode = "RGB"
    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    bg = world.node_tree.nodes.get("Background")
    bg.inputs["Color"].default_value = (0, 0, 0, 1)
    bg.inputs["Strength"].default_value = 0.0
    scene.world = world


def _emission_material(object_id):
    mat = bpy.data.materials.new(f"id_{object_id}")
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    em = nodes.new("ShaderNodeEmission")
    em.inputs["Color"].default_value = (object_id / 255.0, 0.0, 0.0, 1.0)
    em.inputs["Strength"].default_value = 1.0
    mat.node_tree.links.new(em.outputs["Emission"], out.inputs["Surface"])
    return mat


def import_objects(folder, names):
    """Imports every OBJ in `names` (id order) and gives it its id's emission colour."""
    if len(names) > 255:
        raise ValueError("at most 255 objects (ids are encoded as red / 255)")
    for object_id, name in enumerate(names, start=1):
        before = set(bpy.data.objects)
        with quiet():
            bpy.ops.wm.obj_import(filepath=os.path.join(folder, name),
                                  forward_axis="NEGATIVE_Z", up_axis="Y")
        new = [o for o in bpy.data.objects if o not in before]
        if len(new) != 1:
            raise RuntimeError(f"{name}: expected one imported object, got {len(new)}")
        obj = new[0]
        obj.data.materials.clear()
        obj.data.materials.append(_emission_material(object_id))


def place_camera(eye, look_at, up):
    """A camera at `eye` looking at `look_at` with `up` up (flexcam coordinates): its local
    -z is the view direction, +y the image up, +x the image right (Blender's convention)."""
    data = bpy.data.cameras.new("cam")
    cam = bpy.data.objects.new("cam", data)
    bpy.context.scene.collection.objects.link(cam)
    f = (to_blender(look_at) - to_blender(eye)).normalized()
    r = f.cross(to_blender(up)).normalized()
    u = r.cross(f)
    rot = Matrix((r, u, -f)).transposed()
    cam.matrix_world = Matrix.Translation(to_blender(eye)) @ rot.to_4x4()
    data.clip_start = 1e-3
    data.clip_end = 1e4
    bpy.context.scene.camera = cam
    return data


def render_ids(width, height, path):
    """Renders the scene to the EXR `path` and returns its ids as an (height, width) int
    array, row 0 at the top; -1 where the value is not an exact id colour."""
    scene = bpy.context.scene
    scene.render.resolution_x = width
    scene.render.resolution_y = height
    scene.render.filepath = path
    with quiet():
        bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(path, check_existing=False)
    px = np.empty(width * height * 4, dtype=np.float32)
    img.pixels.foreach_get(px)
    bpy.data.images.remove(img)
    px = px.reshape(height, width, 4)[::-1]
    red = px[..., 0] * 255.0
    ids = np.rint(red).astype(np.int64)
    bad = (np.abs(red - ids) > 1e-3) | (np.abs(px[..., 1]) > 1e-6) | (np.abs(px[..., 2]) > 1e-6)
    ids[bad] = -1
    return ids
