#!/bin/sh
# make bench: measures rouge on this machine and prints one markdown table (tools/rouge_bench.c does the
# measuring; docs/bench.md says how to read each row). Timings are reported, never asserted.
#
# Usage: sh tools/bench.sh [BUILD_DIR]       (run from the repository root; `make bench` does)
# Environment: BENCH_QUICK=1 for a short run (fewer repetitions and views: about a minute on llvmpipe;
# the full run takes a few minutes), BENCH_ONLY=size,load,rsf (a subset of the rows: size, convert, load,
# rsf, stamp, memory, frames, env, paint, window, web), RS_SHARED_DATA for the shared scans (default ../shared/data; rows
# that need them say "n/a (shared data absent)" without them), BENCH_FACE (default assets/face.rsf).
# The table also goes to BUILD_DIR/bench.md.
set -u
build=${1:-build}
cd "$(dirname "$0")/.." || exit 1
bench="$build/rouge-bench"
face=${BENCH_FACE:-assets/face.rsf}
[ -x "$bench" ] || { echo "bench: $bench not built (run 'make bench' or 'make BUILD=$build all')" >&2; exit 1; }
[ -f "$face" ] || { echo "bench: no $face" >&2; exit 1; }

quick=""
case "${BENCH_QUICK:-0}" in 0 | "") ;; *) quick=--quick ;; esac
only=""
[ -n "${BENCH_ONLY:-}" ] && only="--only $BENCH_ONLY"
mkdir -p "$build/bench"

# The window row (rouge view --bench-orbit) needs a display: without one, a private Xvfb if installed.
xvfb=""
if [ -z "${DISPLAY:-}" ] && [ -z "${WAYLAND_DISPLAY:-}" ] && command -v Xvfb >/dev/null 2>&1; then
    d=71
    while [ -e "/tmp/.X$d-lock" ] || [ -e "/tmp/.X11-unix/X$d" ]; do d=$((d + 1)); done
    Xvfb ":$d" -screen 0 1024x768x24 -nolisten tcp >"$build/bench/xvfb.log" 2>&1 &
    xvfb=$!
    i=0
    while [ ! -e "/tmp/.X11-unix/X$d" ] && [ $i -lt 50 ]; do sleep 0.1; i=$((i + 1)); done
    if [ -e "/tmp/.X11-unix/X$d" ]; then export DISPLAY=":$d"; else echo "bench: Xvfb did not start" >&2; fi
fi
trap '[ -n "$xvfb" ] && kill "$xvfb" 2>/dev/null; wait 2>/dev/null' EXIT INT TERM

start=$(date +%s)
# shellcheck disable=SC2086
"$bench" --build "$build" --face "$face" --tmp "$build/bench" --out "$build/bench.md" $quick $only
rc=$?
echo
echo "bench: $(($(date +%s) - start)) s${quick:+ (quick)}; table also in $build/bench.md"
exit $rc
