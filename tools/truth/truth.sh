#!/bin/sh
# make truth: the path-traced reference of the bundled head (tests/fixtures/truth/README.md). Renders every bundled
# environment x view with Blender Cycles and writes tests/fixtures/truth/ENV_VIEW.rtf.zst. Slow (about
# TRUTH_SAMPLES x TRUTH_SEEDS x 0.4 s of CPU a view, plus 2 CPU-minutes calibrating the subsurface); never part
# of make test. Each view is the mean of TRUTH_SEEDS independent renders of TRUTH_SAMPLES (render.py).
#   sh tools/truth/truth.sh BUILD_DIR        TRUTH_SAMPLES (1024), TRUTH_SEEDS (2),
#                                            TRUTH_ENVS ("studio daylight office sunset")
# TRUTH_PASSES=1 also writes BUILD_DIR/truth/ENV_VIEW_passes.npz, the light passes (render.py).
set -eu
build=${1:-build}
samples=${TRUTH_SAMPLES:-1024}
seeds=${TRUTH_SEEDS:-2}
envs=${TRUTH_ENVS:-studio daylight office sunset}
size=256
data=../shared/data/leeperrysmith
exr=/usr/share/blender/datafiles/studiolights/world
out=$build/truth
fixtures=tests/fixtures/truth

for f in head_mesh.ply color.png normal.png; do
    if [ ! -f "$data/$f" ]; then
        echo "make truth: $data/$f is missing: the reference renders the scan face.rsf was made from" \
             "(../shared/data/leeperrysmith, see assets/README.md)" >&2
        exit 1
    fi
done
command -v blender >/dev/null 2>&1 || { echo "make truth: no blender (make truth-deps installs Debian's)" >&2; exit 1; }
command -v zstd >/dev/null 2>&1 || { echo "make truth: no zstd (make truth-deps)" >&2; exit 1; }
[ -d "$exr" ] || { echo "make truth: $exr is missing (blender-data)" >&2; exit 1; }

mkdir -p "$out" "$fixtures"
"$build/rouge-truth-scene" assets/face.rsf assets/env "$exr" "$out" "$size"
echo "make truth: the subsurface radius that scatters like rouge's skin profile"
if ! nice -n 15 blender -b --factory-startup --python-exit-code 1 --python tools/truth/sss_calibrate.py -- \
        "$out" "$data" 512 >"$out/sss.log" 2>&1; then
    tail -n 20 "$out/sss.log" >&2
    echo "make truth: blender failed calibrating the subsurface radius (log: $out/sss.log)" >&2
    exit 1
fi
grep '^sss_calibrate: radius' "$out/sss.log"
for env in $envs; do
    echo "make truth: $env ($seeds x $samples samples a pixel)"
    if ! nice -n 15 blender -b --factory-startup --python-exit-code 1 --python tools/truth/render.py -- \
            "$out" "$data" "$env" "$samples" "$out" "$seeds" >"$out/$env.log" 2>&1; then
        tail -n 20 "$out/$env.log" >&2
        echo "make truth: blender failed on $env (log: $out/$env.log)" >&2
        exit 1
    fi
    for f in "$out/${env}"_*.rtf; do
        zstd -q -19 -f "$f" -o "$fixtures/$(basename "$f").zst"
    done
done
echo "make truth: fixtures in $fixtures"
