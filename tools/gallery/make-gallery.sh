#!/usr/bin/env bash
# Renders the pictures of the README's gallery and of the user guide (docs/): each
# multi-perspective example scene beside a perspective view of the same scene, plus the sample
# panorama that `flexcam reproject` examples use (scenes/photos/default-pano.png).
#
#   tools/gallery/make-gallery.sh FLEXCAM
#
# FLEXCAM is a flexcam binary (target/release/flexcam after `cargo build --release`). Writes
# docs/images/gallery/*.png and scenes/photos/default-pano.png, overwriting them; run it from
# anywhere. A perspective view is the example scene file with its [projection] table replaced
# by a pinhole (and, where said, one object changed), written to a temporary folder beside
# links to scenes/models and scenes/surfaces so that relative paths still resolve.
set -euo pipefail
if [ $# -ne 1 ]; then
  echo "usage: $0 FLEXCAM" >&2
  exit 2
fi
flexcam=$(realpath "$1")
cd "$(dirname "$0")/../.."
out=docs/images/gallery
mkdir -p "$out" scenes/photos
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
ln -s "$PWD/scenes/models" "$work/models"
ln -s "$PWD/scenes/surfaces" "$work/surfaces"

# variant SCENE NAME PROJECTION [SED-SCRIPT]: SCENE without its projection tables, then
# PROJECTION (TOML text), optionally edited by SED-SCRIPT; prints the new file's path.
variant() {
  local scene=$1 name=$2 projection=$3 edit=${4:-}
  awk '/^\[+[^]]*\]+/ { skip = ($0 ~ /^\[+projection([].]|$)/) } !skip' "$scene" \
    >"$work/$name.toml"
  printf '\n[projection]\n%s\n' "$projection" >>"$work/$name.toml"
  if [ -n "$edit" ]; then
    sed -i -e "$edit" "$work/$name.toml"
  fi
  echo "$work/$name.toml"
}

render() {
  "$flexcam" render "$@" >/dev/null
}

small=(--width 320 --height 240)

# Twist and crossed slits: the preset's own eye and look-at, as a 60-degree pinhole.
cube_view='type = "perspective"
position = [0.0, 5.5, 7.0]
look_at = [0.0, 0.4, 0.0]
fov = 60.0'
render scenes/flexible-twist.toml -o "$out/twist.png"
render "$(variant scenes/flexible-twist.toml twist-persp "$cube_view")" -o "$out/twist-perspective.png"
render scenes/flexible-crossed-slits.toml "${small[@]}" -o "$out/crossed-slits.png"
render "$(variant scenes/flexible-crossed-slits.toml slits-persp "$cube_view")" "${small[@]}" \
  -o "$out/crossed-slits-perspective.png"

# Equal area: the whole sphere of directions; the pinhole looks at the map's centre.
render scenes/flexible-equal-area.toml -o "$out/equal-area.png"
render "$(variant scenes/flexible-equal-area.toml area-persp 'type = "perspective"
position = [0.0, 3.5, 3.0]
look_at = [0.0, 1.0, 0.0]
fov = 90.0')" "${small[@]}" -o "$out/equal-area-perspective.png"

# Inward sphere: rays from a sphere of radius 6 to its centre; the pinhole stands outside.
render scenes/trilinear-inward-sphere.toml -o "$out/inward-sphere.png"
render "$(variant scenes/trilinear-inward-sphere.toml sphere-persp 'type = "perspective"
position = [0.0, 4.5, 6.0]
look_at = [0.0, 0.5, 0.0]
fov = 50.0')" "${small[@]}" -o "$out/inward-sphere-perspective.png"

# Detail in context: the grid's own camera as a pinhole.
render scenes/trilinear-detail-in-context.toml -o "$out/detail-in-context.png"
render "$(variant scenes/trilinear-detail-in-context.toml detail-persp 'type = "perspective"
position = [0.0, 5.0, 9.0]
look_at = [0.0, 0.5, 0.0]
fov = 60.0')" -o "$out/detail-in-context-perspective.png"

# Detail in context with an inverse-perspective focus (beside the same pinhole as above).
render scenes/trilinear-detail-inverse-perspective.toml --method trilinear \
  -o "$out/detail-inverse-perspective.png"

# Views through a ball: the trilinear grid, and beside it a 90-degree pinhole at the grid's
# eye looking at a real mirror (glass) sphere of the ball's size and place, ray cast.
ball_views=(
  'mirror [0.4, 1.5, 1.6] [0.0, 1.0, 0.0]'
  'glass [0.3, 2.0, 2.6] [0.0, 1.6, 0.0]'
)
for view in "${ball_views[@]}"; do
  optic=${view%% *}
  eye=$(echo "$view" | sed 's/^[a-z]* \(\[[^]]*\]\) .*/\1/')
  center=${view##* [}
  center="[$center"
  printf '\n[[object]]\nname = "ball"\nshape = "sphere"\nsize = 1.0\ntessellation = 96\nmaterial = "%s"\ncolor = [0.95, 0.95, 0.95]\ntranslate = %s\n' \
    "$optic" "$center" >"$work/ball-$optic.toml"
  render "scenes/trilinear-sphere-$optic.toml" --method trilinear -o "$out/sphere-$optic.png"
  render "$(variant "scenes/trilinear-sphere-$optic.toml" "sphere-$optic-persp" "type = \"perspective\"
position = $eye
look_at = $center
fov = 90.0" "\$r $work/ball-$optic.toml")" -o "$out/sphere-$optic-perspective.png"
done

# Multi-hit reflection: the mirror ball with a second one behind the camera, and beside it
# the same 90-degree pinhole with both as real mirror spheres, ray cast.
printf '\n[[object]]\nname = "ball"\nshape = "sphere"\nsize = 1.0\ntessellation = 96\nmaterial = "mirror"\ncolor = [0.95, 0.95, 0.95]\ntranslate = [0.0, 1.0, 0.0]\n\n[[object]]\nname = "second ball"\nshape = "sphere"\nsize = 1.2\ntessellation = 96\nmaterial = "mirror"\ncolor = [0.95, 0.95, 0.95]\ntranslate = [-0.6, 1.6, 3.6]\n' \
  >"$work/balls-twice.toml"
render scenes/trilinear-sphere-mirror-twice.toml --method trilinear -o "$out/sphere-mirror-twice.png"
render "$(variant scenes/trilinear-sphere-mirror-twice.toml sphere-twice-persp 'type = "perspective"
position = [0.4, 1.5, 1.6]
look_at = [0.0, 1.0, 0.0]
fov = 90.0' "\$r $work/balls-twice.toml")" -o "$out/sphere-mirror-twice-perspective.png"

# Funny mirror: beside it the same camera looking at a flat mirror box of the same size.
mirror_view=$(sed -n '/^\[projection\]/,/^$/p' scenes/reflect-funny-mirror.toml | sed 1d)
render scenes/reflect-funny-mirror.toml -o "$out/funny-mirror.png"
render "$(variant scenes/reflect-funny-mirror.toml mirror-flat "$mirror_view" \
  's|^shape = "mesh"|shape = "box"|; s|^file = "models/funny-mirror.obj"|size = [2.0, 2.0, 0.02]|; /^trilinear_reflector/d')" \
  -o "$out/funny-mirror-perspective.png"

# Lens: beside it the same camera without the lens (the object named "lens" removed).
lens_view=$(sed -n '/^\[projection\]/,/^$/p' scenes/refract-lens.toml | sed 1d)
render scenes/refract-lens.toml -o "$out/lens.png"
render "$(variant scenes/refract-lens.toml lens-none "$lens_view" \
  '/^\[\[object\]\]$/{N;/name = "lens"/{:a;N;/\n$/!ba;d}}')" -o "$out/lens-perspective.png"

# Panorama with a local perspective edit: the edited panorama, the same panorama unedited, and
# a pinhole at the panorama's eye looking at the edited wall.
render scenes/flexible-panorama-edit.toml -o "$out/panorama-edit.png"
render "$(variant scenes/flexible-panorama-edit.toml pano-plain "$(sed -n '/^\[projection\]/,/^$/p' \
  scenes/flexible-panorama-edit.toml | sed 1d | grep -v '^perspective_rect')")" \
  -o "$out/panorama-unedited.png"
render "$(variant scenes/flexible-panorama-edit.toml pano-persp 'type = "perspective"
position = [0.0, 1.5, 0.0]
look_at = [0.0, 1.5, -1.0]
fov = 90.0')" "${small[@]}" -o "$out/panorama-edit-perspective.png"

# The user guide's pictures (docs/*.md), each at a small size.
# Cameras: the teapot-room objects through each single-viewpoint type.
room_eye='position = [0.0, 2.6, 6.5]
look_at = [0.0, 0.6, 0.0]'
render builtin:teapot-room "${small[@]}" -o "$out/teapot-perspective.png"
render scenes/cameras/teapot-fisheye.toml --width 240 --height 240 -o "$out/teapot-fisheye.png"
# Calibrated lenses: barrel distortion beside the undistorted pinhole of the same fx, and the
# Kannala-Brandt fisheye.
render scenes/cameras/opencv-checker.toml -o "$out/opencv-checker.png"
render "$(variant scenes/cameras/opencv-checker.toml checker-persp 'type = "perspective"
position = [0.0, 3.0, 0.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 0.0, -1.0]
fov = 77.3196')" -o "$out/opencv-checker-perspective.png"
render scenes/cameras/opencv-fisheye-teapot.toml --width 240 --height 240 -o "$out/opencv-fisheye-teapot.png"
# The fisheye mappings at fov 180, the sensor ellipse, Cycles' lens polynomial and the dome
# master.
for mapping in equisolid stereographic orthographic; do
  render scenes/cameras/teapot-fisheye.toml -D "projection.mapping=$mapping" --width 240 --height 240 \
    -o "$out/fisheye-$mapping.png"
done
render scenes/cameras/teapot-fisheye.toml -D projection.fit=fill --width 320 --height 192 -o "$out/fisheye-fill.png"
render scenes/cameras/fisheye-polynomial-teapot.toml --width 320 --height 240 -o "$out/fisheye-polynomial-teapot.png"
render scenes/cameras/dome-master-teapot.toml --width 240 --height 240 -o "$out/dome-master-teapot.png"
render "$(variant scenes/teapot-room.toml room-ortho "type = \"orthographic\"
$room_eye
width = 7.0")" "${small[@]}" -o "$out/teapot-orthographic.png"
pano_eye='position = [0.0, 1.0, 1.8]
look_at = [0.0, 0.6, 0.0]'
render "$(variant scenes/teapot-room.toml room-equirect "type = \"equirectangular\"
$pano_eye")" --width 320 --height 160 -o "$out/teapot-equirectangular.png"
render "$(variant scenes/teapot-room.toml room-cylindrical "type = \"cylindrical\"
$pano_eye")" --width 320 --height 120 -o "$out/teapot-cylindrical.png"

# The cube-floor scene from its own camera: the perspective view beside the trilinear and
# flexible examples that share its objects.
render builtin:cube-floor --width 240 --height 240 -o "$out/cube-floor-perspective.png"
for scene in trilinear-fan trilinear-grid-cylinder trilinear-two-views reflect-sphere-cube \
  flexible-isometric flexible-magnifier flexible-occlusion flexible-ortho-near-persp-far \
  flexible-depth-transition flexible-mcop flexible-bent flexible-quadratic flexible-patches \
  flexible-panorama-cubic flexible-panorama-custom flexible-panorama-cylindrical-edit \
  flexible-projector-fit flexible-projector-fit-curved; do
  size=()
  case $scene in
    trilinear-fan | flexible-bent) size=(--width 300 --height 200) ;;
  esac
  render "scenes/$scene.toml" "${size[@]}" -o "$out/$scene.png"
done
"$flexcam" animate scenes/flexible-animation.toml --gif "$out/flexible-animation.gif" >/dev/null

# Chapter 6 (docs/flexible.md): the pieces examples, Digital Cubism's NURBS surfaces and the
# long scene, each beside a pinhole (the single-centre eye; the GLC mosaic's eye over its
# whole image plane; the NURBS near arc's centre) or, for the long scene, the pushbroom.
for scene in flexible-single-centre flexible-collage flexible-glc-mosaic flexible-nurbs \
  flexible-long-scene; do
  render "scenes/$scene.toml" -o "$out/$scene.png"
done
render "$(variant scenes/flexible-single-centre.toml centre-persp 'type = "perspective"
position = [0.0, 2.5, 7.0]
look_at = [0.0, 1.0, 0.0]
fov = 60.0')" -o "$out/flexible-single-centre-perspective.png"
render "$(variant scenes/flexible-glc-mosaic.toml mosaic-persp 'type = "perspective"
position = [0.0, 1.8425356250363332, 6.970142500145332]
look_at = [0.0, -0.6574643749636668, -3.029857499854668]
fov = 112.61986494804043')" -o "$out/flexible-glc-mosaic-perspective.png"
render "$(variant scenes/flexible-nurbs.toml nurbs-persp 'type = "perspective"
position = [0.0, 1.5, 6.0]
look_at = [0.0, 1.0, 0.0]
fov = 90.0')" -o "$out/flexible-nurbs-perspective.png"
render "$(variant scenes/flexible-long-scene.toml street-pushbroom 'type = "flexible"
preset = "pushbroom"
position = [0.0, 2.5, 3.0]
look_at = [0.0, 2.5, 0.0]
width = 100.0
v_fov = 90.0
clip = [0.0, 25.0]')" -o "$out/flexible-long-scene-pushbroom.png"

# Renderers: the difference images of `flexcam compare` (id mismatches red).
"$flexcam" compare scenes/trilinear-fan.toml --method trilinear --width 300 --height 200 \
  --diff "$out/diff-trilinear-fan.png" >/dev/null
"$flexcam" compare scenes/cameras/teapot-fisheye.toml --method raster --width 240 --height 240 \
  --diff "$out/diff-raster-fisheye.png" >/dev/null

# The sample equirectangular photo for `flexcam reproject`: the default scene, 512 x 256, and
# what the reprojection examples of the guide make of it.
"$flexcam" render --width 512 --height 256 -o scenes/photos/default-pano.png >/dev/null
"$flexcam" reproject --input scenes/photos/default-pano.png scenes/flexible-mcop.toml \
  -o "$out/reproject-mcop.png" >/dev/null
"$flexcam" reproject --input scenes/photos/default-pano.png scenes/cameras/teapot-fisheye.toml \
  --width 240 --height 240 -o "$out/reproject-fisheye.png" >/dev/null

du -ch "$out"/* scenes/photos/* | tail -1
