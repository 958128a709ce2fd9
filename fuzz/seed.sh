#!/bin/sh
# Seeds fuzz/corpus/TARGET from the example scenes and models (scenes/, scenes/models/).
set -e
cd "$(dirname "$0")"
for target in scene_file obj mtl ply gltf glb; do mkdir -p "corpus/$target"; done
cp ../scenes/*.toml corpus/scene_file/
for ext in obj mtl ply gltf glb; do
    for f in ../scenes/models/*."$ext" ../scenes/surfaces/*."$ext"; do
        [ -f "$f" ] && cp "$f" "corpus/$ext/"
    done
done
true
