"""POV-Ray cameras equivalent to flexcam's standard projections (audit 4, item 4).

Each function takes the scene's `[projection]` table and the image size and returns the POV-Ray
`camera { ... }` block, or None when POV-Ray has no equivalent. Handedness: POV-Ray is
left-handed, so flexcam's (right-handed) image right is POV-Ray's `right` with a minus sign
(`right -x * ...`), which the renders confirm (README.md, docs/robustness.md). Not mapped:
ultra_wide_angle, omnimax, panoramic (= equirectangular with h_fov = v_fov = 180, not tried),
cylinder 2 to 4 (no flexcam projection of the same name).
"""

from __future__ import annotations

import math


def _vec(v) -> str:
    return "<" + ", ".join(f"{float(x):.17g}" for x in v) + ">"


def _frame(proj: dict, sky_sign: float = 1.0) -> str:
    sky = [sky_sign * float(c) for c in proj.get("up", [0.0, 1.0, 0.0])]
    return f"location {_vec(proj['position'])} sky {_vec(sky)} look_at {_vec(proj['look_at'])}"


# A `flexible` projection with one of these presets and only these keys is the standard type
# of the same name (docs/flexible.md: same rays after normalisation, tested in flexcam), as
# long as its near clip is 0 (POV-Ray has no near clip; the far clip, 1000 by default, is
# beyond every scene here).
SAME_AS_TYPE = {"perspective", "orthographic", "fisheye", "equirectangular", "cylindrical"}
PRESET_KEYS = {"type", "preset", "position", "look_at", "up", "clip", "fov", "width", "h_fov", "v_fov"}


def camera(proj: dict, width: int, height: int) -> str | None:
    kind, aspect = proj.get("type"), width / height
    if kind == "flexible":
        if proj.get("preset") not in SAME_AS_TYPE or set(proj) - PRESET_KEYS:
            return None
        if proj.get("clip", [0.0])[0] != 0:
            return None
        kind = proj["preset"]
    sky_sign = 1.0
    if kind == "perspective":
        head = f"perspective right -x * {aspect:.17g} up y angle {float(proj['fov']):.17g}"
    elif kind == "orthographic":
        w = float(proj["width"])
        head = f"orthographic right -x * {w:.17g} up y * {w / aspect:.17g}"
    elif kind == "fisheye":
        # POV-Ray scales x and y by the lengths of right and up: the circle of radius 1 is
        # then inscribed in the shorter side, as flexcam's.
        rx, uy = max(aspect, 1.0), max(1.0 / aspect, 1.0)
        head = f"fisheye right -x * {rx:.17g} up y * {uy:.17g} angle {float(proj['fov']):.17g}"
    elif kind == "equirectangular":
        h, v = float(proj.get("h_fov", 360.0)), float(proj.get("v_fov", 180.0))
        # spherical turns by the longitude about its up vector and by the latitude about its
        # right vector in POV-Ray's sense: with `right -x` both come out mirrored unless the
        # sky is reversed (found by trying the four sign pairs; only this one matches).
        head = f"spherical right -x * {aspect:.17g} up y angle {h:.17g} {v:.17g}"
        sky_sign = -1.0
    elif kind == "cylindrical":
        h, v = float(proj.get("h_fov", 360.0)), float(proj.get("v_fov", 90.0))
        # cylinder 1: longitude linear in x over `angle`, height y0 * |up| for y0 in
        # [-0.5, 0.5]; flexcam's top row is at height tan(v_fov / 2).
        head = f"cylinder 1 right -x up y * {2 * math.tan(math.radians(v / 2)):.17g} angle {h:.17g}"
    else:
        return None
    return f"camera {{ {head} {_frame(proj, sky_sign)} }}"
