#!/bin/sh
# Runs one fuzz target for SECONDS (default 120) on the seeded corpus, one job, 2 GB RSS
# and 10 s per input at most: fuzz/run.sh TARGET [SECONDS]. The model targets run under
# AddressSanitizer; scene_file runs without it and with 60 s an input: a scene may fit a
# curved projector grid, up to about 3 s of legitimate work in the release binary on
# mutated data and 15 to 30 times that under the sanitizer, so that its runs stopped on
# such inputs within minutes (panics, hangs and runaway memory still stop the run).
# Needs the nightly toolchain and cargo-fuzz (`cargo install cargo-fuzz`).
set -e
cd "$(dirname "$0")/.."
target=${1:?usage: fuzz/run.sh TARGET [SECONDS] (targets: scene_file obj mtl ply gltf glb)}
seconds=${2:-120}
per_input=10
sanitizer=address
if [ "$target" = scene_file ]; then per_input=60; sanitizer=none; fi
[ -d "fuzz/corpus/$target" ] || fuzz/seed.sh
exec cargo +nightly fuzz run --sanitizer "$sanitizer" "$target" "fuzz/corpus/$target" -- \
    -max_total_time="$seconds" -rss_limit_mb=2048 -timeout="$per_input" -max_len=65536
