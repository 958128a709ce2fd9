#!/bin/sh
# Seeds fuzz/corpus/TARGET from the example scenes and models (scenes/, scenes/models/).
set -e
cd "$(dirname "$0")"
for target in scene_file obj mtl ply gltf glb; do mkdir -p "corpus/$target"; done
# Every example scene but painting-bedroom: its 30-click fit (starts = "auto" fits four
# models with held-out folds) takes longer than run.sh's 10 s per input under the
# sanitizer's instrumentation; the other fit scenes cover the fitting code.
for f in ../scenes/*.toml; do
    case "$f" in */painting-bedroom.toml) ;; *) cp "$f" corpus/scene_file/ ;; esac
done
for ext in obj mtl ply gltf glb; do
    for f in ../scenes/models/*."$ext" ../scenes/surfaces/*."$ext"; do
        [ -f "$f" ] && cp "$f" "corpus/$ext/"
    done
done
true
