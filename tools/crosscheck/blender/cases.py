"""The camera pairs compared: a Blender camera setting and the flexcam projection that should
be the same projection (same orientation, field of view, centre and aspect).

Each case gives the image size, a function that sets up the Blender camera data (`cam`, a
bpy.types.Camera; `frame` holds the flexcam camera frame) and the flexcam `[projection]`
keys besides `type`, `position`, `look_at` and `up`. The mappings (Cycles' formulas in
intern/cycles/kernel/camera/projection.h and blender/camera.cpp):

- perspective: `angle` with `sensor_fit = HORIZONTAL` is flexcam's horizontal `fov`;
- shift: Blender's `shift_x`, `shift_y` are in units of the larger image side (auto fit),
  flexcam's `off_axis` shift in half-widths and half-heights: sx = 2 shift_x W / max(W, H),
  sy = 2 shift_y W / H for W >= H;
- orthographic: `ortho_scale` is the larger image side's extent (auto fit): flexcam `width`
  for W >= H;
- equirectangular: longitude grows to the right, latitude up, both measured in the camera's
  own frame (the pole is the camera's up); symmetric ranges are flexcam's `h_fov`, `v_fov`,
  asymmetric ones a `sphere` far surface with those ranges, `axis` the camera up and
  `front` the view direction;
- fisheye equidistant: u, v in [0, 1] over the whole image are scaled to [-1, 1] each, the
  rim r = 1 is `fisheye_fov` / 2 off the axis; on a square image that is flexcam's fisheye
  (circle inscribed in the shorter side, angle v fov / 2 with v = r); on a non-square
  image Cycles' "circle" is an ellipse filling the image (no flexcam equivalent);
- fisheye lens polynomial: theta = -(k0 + k1 r + ... + k4 r^4), r in mm on the sensor
  (`sensor_fit = HORIZONTAL`: width `sensor_width`, height `sensor_width` H / W), cut at
  |theta| > `fisheye_fov` / 2; with R the inscribed circle's radius in mm, k1 = -(fov/2)/R
  is flexcam's fisheye (polar, v = r / R) and k1 = -(fov/2) / (4R), k2 = -3 (fov/2) / (4R^2)
  its `reparam = "lens"` (v = r/4 + 3 r^2/4), on any aspect;
- fisheye equisolid: u, v scaled to mm on the sensor as above, theta = 2 asin(r / (2 lens)),
  cut at r > 2 lens sin(fov / 4): with lens = R / (2 sin(fov / 4)) the rim is the inscribed
  circle and theta = 2 asin((r / R) sin(fov / 4)), flexcam's fisheye with
  `reparam = "equisolid"`, on any aspect;
- mirror ball: u, v in [0, 1] over the whole image scaled to [-1, 1] each, the direction the
  reflection of the view ray off a unit ball, i.e. 2 asin(r) off the view axis: the
  360-degree equisolid fisheye, flexcam's fisheye with fov 360 and `reparam = "equisolid"`
  on a square image (measured: the view direction is the image centre, the camera's right
  at the image's right, up up; on other aspects Cycles' circle is an ellipse);
- equiangular cubemap face: dir = (1, tan((1/2 - u) pi/2), tan((v - 1/2) pi/2)), angles
  linear in u and v over 90 degrees: flexcam's perspective preset with fov 90 and
  `reparam = "equiangular"` on a square image;
- central cylindrical: longitude range (radians) and height range (height / radius, i.e.
  tan of the elevation), linear in u and v: flexcam's `cylindrical` with
  h_fov = u_max - u_min, tan(v_fov / 2) = v_max for symmetric ranges.
"""

import math


def _fmt(v):
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_fmt(x) for x in v) + "]"
    if isinstance(v, str):
        return f'"{v}"'
    return repr(float(v))


def keys(**kw):
    """flexcam projection keys as TOML lines."""
    return "".join(f"{k} = {_fmt(v)}\n" for k, v in kw.items())


def _perspective(cam, frame):
    cam.type = "PERSP"
    cam.sensor_fit = "HORIZONTAL"
    cam.angle = math.radians(70.0)


def _off_axis(cam, frame):
    cam.type = "PERSP"
    cam.sensor_fit = "AUTO"
    cam.angle = math.radians(70.0)
    cam.shift_x = 0.1
    cam.shift_y = -0.08


def _ortho(cam, frame):
    cam.type = "ORTHO"
    cam.sensor_fit = "AUTO"
    cam.ortho_scale = 6.0


def _pano(cam, kind):
    cam.type = "PANO"
    cam.panorama_type = kind


def _equirect(lon, lat):
    def setup(cam, frame):
        _pano(cam, "EQUIRECTANGULAR")
        cam.longitude_min, cam.longitude_max = (math.radians(a) for a in lon)
        cam.latitude_min, cam.latitude_max = (math.radians(a) for a in lat)
    return setup


def _equidistant(fov):
    def setup(cam, frame):
        _pano(cam, "FISHEYE_EQUIDISTANT")
        cam.fisheye_fov = math.radians(fov)
    return setup


SENSOR_WIDTH = 36.0


def _inscribed_radius_mm(width, height):
    return 0.5 * min(width, height) * SENSOR_WIDTH / width


def _polynomial(fov, width, height, lens_like):
    def setup(cam, frame):
        _pano(cam, "FISHEYE_LENS_POLYNOMIAL")
        cam.sensor_fit = "HORIZONTAL"
        cam.sensor_width = SENSOR_WIDTH
        cam.fisheye_fov = math.radians(fov)
        half = 0.5 * math.radians(fov)
        r = _inscribed_radius_mm(width, height)
        cam.fisheye_polynomial_k0 = 0.0
        if lens_like:
            cam.fisheye_polynomial_k1 = -half / (4.0 * r)
            cam.fisheye_polynomial_k2 = -3.0 * half / (4.0 * r * r)
        else:
            cam.fisheye_polynomial_k1 = -half / r
            cam.fisheye_polynomial_k2 = 0.0
        cam.fisheye_polynomial_k3 = 0.0
        cam.fisheye_polynomial_k4 = 0.0
    return setup


def _equisolid(fov, width, height):
    def setup(cam, frame):
        _pano(cam, "FISHEYE_EQUISOLID")
        cam.sensor_fit = "HORIZONTAL"
        cam.sensor_width = SENSOR_WIDTH
        cam.fisheye_fov = math.radians(fov)
        # Cycles' rim is at r = 2 lens sin(fov / 4) mm: put it on the inscribed circle.
        r = _inscribed_radius_mm(width, height)
        cam.fisheye_lens = r / (2.0 * math.sin(math.radians(fov) / 4.0))
    return setup


def _mirror_ball(cam, frame):
    _pano(cam, "MIRRORBALL")


def _equiangular_face(cam, frame):
    _pano(cam, "EQUIANGULAR_CUBEMAP_FACE")


def _central_cylindrical(h_fov, v_fov):
    def setup(cam, frame):
        _pano(cam, "CENTRAL_CYLINDRICAL")
        cam.central_cylindrical_range_u_min = math.radians(-0.5 * h_fov)
        cam.central_cylindrical_range_u_max = math.radians(0.5 * h_fov)
        t = math.tan(math.radians(0.5 * v_fov))
        cam.central_cylindrical_range_v_min = -t
        cam.central_cylindrical_range_v_max = t
        cam.central_cylindrical_radius = 1.0
    return setup


def _sphere_far(lon, lat):
    """flexcam keys for a pinhole to a sphere window (frame: the camera frame)."""
    def projection(frame):
        eye, up, fwd = frame["eye"], frame["up"], frame["forward"]
        return (
            f"near = {{ surface = \"point\", point = {_fmt(eye)} }}\n"
            f"far = {{ surface = \"sphere\", center = {_fmt(eye)}, radius = 1000.0, "
            f"longitude = {_fmt(lon)}, latitude = {_fmt(lat)}, axis = {_fmt(up)}, "
            f"front = {_fmt(fwd)} }}\n"
        )
    return projection


def _preset(name, **kw):
    return lambda frame: keys(preset=name, **kw)


def all_cases():
    """(name, blender text, flexcam text, width, height, blender setup, flexcam keys(frame))."""
    w, h = 320, 240
    return [
        ("perspective", "PERSP, sensor_fit HORIZONTAL, angle 70", 'preset "perspective", fov 70',
         w, h, _perspective, _preset("perspective", fov=70.0)),
        ("off_axis", "PERSP, angle 70, shift_x 0.1, shift_y -0.08",
         'preset "off_axis", fov 70, shift [0.2, -0.2133]', w, h, _off_axis,
         _preset("off_axis", fov=70.0, shift=[0.2, -0.16 * w / h])),
        ("orthographic", "ORTHO, ortho_scale 6", 'preset "orthographic", width 6', w, h,
         _ortho, _preset("orthographic", width=6.0)),
        ("equirect_full", "EQUIRECTANGULAR, lon [-180, 180], lat [-90, 90]",
         'preset "equirectangular"', 480, 240, _equirect((-180, 180), (-90, 90)),
         _preset("equirectangular")),
        ("equirect_window", "EQUIRECTANGULAR, lon [-100, 100], lat [-50, 50]",
         'preset "equirectangular", h_fov 200, v_fov 100', 400, 200,
         _equirect((-100, 100), (-50, 50)), _preset("equirectangular", h_fov=200.0, v_fov=100.0)),
        ("equirect_asym", "EQUIRECTANGULAR, lon [-120, 60], lat [-30, 70]",
         'near point, far sphere, longitude [-120, 60], latitude [-30, 70]', 360, 200,
         _equirect((-120, 60), (-30, 70)), _sphere_far([-120.0, 60.0], [-30.0, 70.0])),
        ("fisheye_equidistant_180", "FISHEYE_EQUIDISTANT, fov 180 (square image)",
         'preset "fisheye", fov 180', 256, 256, _equidistant(180.0),
         _preset("fisheye", fov=180.0)),
        ("fisheye_equidistant_280", "FISHEYE_EQUIDISTANT, fov 280 (square image)",
         'preset "fisheye", fov 280', 256, 256, _equidistant(280.0),
         _preset("fisheye", fov=280.0)),
        ("fisheye_equidistant_wide", "FISHEYE_EQUIDISTANT, fov 180, 320 x 240",
         'preset "fisheye", fov 180 (Cycles: an ellipse filling the image)', w, h,
         _equidistant(180.0), _preset("fisheye", fov=180.0)),
        ("polynomial_equidistant", "FISHEYE_LENS_POLYNOMIAL, fov 200, k1 = -(fov/2)/R",
         'preset "fisheye", fov 200', w, h, _polynomial(200.0, w, h, False),
         _preset("fisheye", fov=200.0)),
        ("polynomial_lens", "FISHEYE_LENS_POLYNOMIAL, fov 180, k1 = -(fov/2)/(4R), "
         "k2 = -3(fov/2)/(4R^2)", 'preset "fisheye", fov 180, reparam "lens"', w, h,
         _polynomial(180.0, w, h, True), _preset("fisheye", fov=180.0, reparam="lens")),
        ("fisheye_equisolid_180", "FISHEYE_EQUISOLID, fov 180, lens = R / (2 sin(fov/4))",
         'preset "fisheye", fov 180, reparam "equisolid"', w, h, _equisolid(180.0, w, h),
         _preset("fisheye", fov=180.0, reparam="equisolid")),
        ("fisheye_equisolid_300", "FISHEYE_EQUISOLID, fov 300, lens = R / (2 sin(fov/4))",
         'preset "fisheye", fov 300, reparam "equisolid"', w, h, _equisolid(300.0, w, h),
         _preset("fisheye", fov=300.0, reparam="equisolid")),
        ("mirror_ball", "MIRRORBALL (square image)",
         'preset "fisheye", fov 360, reparam "equisolid"', 256, 256, _mirror_ball,
         _preset("fisheye", fov=360.0, reparam="equisolid")),
        ("equiangular_face", "EQUIANGULAR_CUBEMAP_FACE (square image)",
         'preset "perspective", fov 90, reparam "equiangular"', 256, 256, _equiangular_face,
         _preset("perspective", fov=90.0, reparam="equiangular")),
        ("central_cylindrical", "CENTRAL_CYLINDRICAL, u [-150, 150], v [-tan 50, tan 50]",
         'preset "cylindrical", h_fov 300, v_fov 100', 480, 240,
         _central_cylindrical(300.0, 100.0), _preset("cylindrical", h_fov=300.0, v_fov=100.0)),
    ]


def controls():
    """Negative controls: each is a case above with the flexcam side slightly wrong (half a
    degree of field of view, a mirrored longitude range, a 1-degree turn), which the
    comparison must report as disagreeing beyond edge pixels."""
    w, h = 320, 240
    return [
        ("control_fov", "PERSP, angle 70", 'preset "perspective", fov 70.5 (wrong)', w, h,
         _perspective, _preset("perspective", fov=70.5)),
        ("control_equiangular", "EQUIANGULAR_CUBEMAP_FACE (square image)",
         'preset "perspective", fov 90 (tangents linear, wrong)', 256, 256, _equiangular_face,
         _preset("perspective", fov=90.0)),
        ("control_mirrored", "EQUIRECTANGULAR, lon [-120, 60], lat [-30, 70]",
         "far sphere, longitude [60, -120] (mirrored, wrong)", 360, 200,
         _equirect((-120, 60), (-30, 70)), _sphere_far([60.0, -120.0], [-30.0, 70.0])),
        ("control_turn", "EQUIRECTANGULAR, lon [-180, 180], lat [-90, 90]",
         "far sphere, longitude [-179, 181] (turned 1 degree, wrong)", 480, 240,
         _equirect((-180, 180), (-90, 90)), _sphere_far([-179.0, 181.0], [-90.0, 90.0])),
    ]
