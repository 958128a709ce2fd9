#!/bin/sh
# Runs one fuzz target for SECONDS (default 120) on the seeded corpus, one job, 2 GB RSS
# and 10 s per input at most: fuzz/run.sh TARGET [SECONDS]. Needs the nightly toolchain
# and cargo-fuzz (`cargo install cargo-fuzz`).
set -e
cd "$(dirname "$0")/.."
target=${1:?usage: fuzz/run.sh TARGET [SECONDS] (targets: scene_file obj mtl ply gltf glb)}
seconds=${2:-120}
[ -d "fuzz/corpus/$target" ] || fuzz/seed.sh
exec cargo +nightly fuzz run "$target" "fuzz/corpus/$target" -- \
    -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 -max_len=65536
