#!/bin/sh
# test_cold_cache.sh — what a new machine meets: the GL programs run with an empty Mesa shader cache and an
# empty HOME / XDG_CACHE_HOME, and render the same picture as with the cache the suite has warmed; the
# valgrind test runs with the disk cache off (Mesa's cache writer trips valgrind on its own bytes).
# Usage: sh tests/test_cold_cache.sh BUILD_DIR [NAME_FILTER...]
build=${1:-build}
[ $# -gt 0 ] && shift
filters="$*"
selected() {
    [ -z "$filters" ] && return 0
    for f in $filters; do case "$1" in *"$f"*) return 0 ;; esac; done
    return 1
}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
rouge="$build/rouge"

if selected cold_cache_render_matches_warm; then
    "$build/rouge-pack" tests/fixtures/ply/mesh_st.ply --points 3000 -o "$tmp/face.rsf" -q 2>/dev/null
    args="render $tmp/face.rsf --size 48x48 --pipeline mobile"
    # shellcheck disable=SC2086
    "$rouge" $args -o "$tmp/warm.png" >"$tmp/warm.log" 2>&1
    mkdir -p "$tmp/home" "$tmp/cache" "$tmp/mesa"
    # shellcheck disable=SC2086
    HOME="$tmp/home" XDG_CACHE_HOME="$tmp/cache" MESA_SHADER_CACHE_DIR="$tmp/mesa" \
        "$rouge" $args -o "$tmp/cold.png" >"$tmp/cold.log" 2>&1
    rc=$?
    if [ $rc -ne 0 ]; then
        echo "FAIL - cold_cache_render_matches_warm: exit $rc with an empty cache: $(head -c 300 "$tmp/cold.log")"
    elif ! cmp -s "$tmp/warm.png" "$tmp/cold.png"; then
        echo "FAIL - cold_cache_render_matches_warm: the cold-cache render differs: $("$build/rouge-imgdiff" "$tmp/warm.png" "$tmp/cold.png" 2>&1 | head -1)"
    else
        echo "ok - cold_cache_render_matches_warm"
    fi
fi

if selected cold_cache_valgrind_runs_with_the_disk_cache_off; then
    if grep -q '^export MESA_SHADER_CACHE_DISABLE=true' tests/test_valgrind.sh &&
        grep -q 'MESA_SHADER_CACHE_DIR="$fresh/mesa"' .ci/run; then
        echo "ok - cold_cache_valgrind_runs_with_the_disk_cache_off"
    else
        echo "FAIL - cold_cache_valgrind_runs_with_the_disk_cache_off: tests/test_valgrind.sh must disable Mesa's disk cache and .ci/run must start from empty caches"
    fi
fi
exit 0
