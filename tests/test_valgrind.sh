#!/bin/sh
# test_valgrind.sh — valgrind memcheck of the real programs: a conversion (cloud without normals, and a
# textured mesh with every map), a headless render that loads a look, paints a stroke and saves the look
# (mobile pipeline), rouge-imgdiff, and the error paths of hostile inputs. Each must end with zero memory
# errors and zero leaks in rouge's code. The GL stack (glvnd, Mesa, LLVM) keeps memory for the life
# of the process and trips valgrind in places: tests/valgrind.supp suppresses only stacks that pass
# through those libraries.
#
# Kept small to fit `make test` (~60 CPU-s on one core, most of them the render: any GL process's start-up
# under memcheck, then the studio environment, look and strokes; its 48x48 picture gets a 512^2 shadow
# map): the render uses a 3000-splat face converted here.
# RS_VALGRIND_FACE=1 (make test-full) adds the bundled 600k face at --max-splats 2000 (~90 s: loading and
# uploading 600k splats under valgrind); docs/robustness.md records its result.
# Usage: sh tests/test_valgrind.sh BUILD_DIR [NAME_FILTER...]   (run from the repository root)
build=${1:-build}
[ $# -gt 0 ] && shift
filters="$*"
rouge="$build/rouge"
pack="$build/rouge-pack"
imgdiff="$build/rouge-imgdiff"
fx=tests/fixtures
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# Mesa's shader disk cache checks its blobs with valgrind client requests and trips on its own padding
# bytes whenever it writes an entry (a cold cache: every new machine). Those are Mesa's bytes, not ours;
# with the disk cache off the driver never takes that path, so no suppression is needed for it.
export MESA_SHADER_CACHE_DISABLE=true MESA_GLSL_CACHE_DISABLE=true
# llvmpipe's LLVM optimisation passes are most of a GL process's time under valgrind; without them
# (GALLIVM_PERF=nopt: Mesa's JIT only, rouge's code runs the same) the render costs ~95 CPU-s, not ~145.
export GALLIVM_PERF=nopt
out="${RS_TEST_OUT:-$build/test-out}/valgrind"
mkdir -p "$out"

selected() {
    [ -z "$filters" ] && return 0
    for f in $filters; do
        case "$1" in *"$f"*) return 0 ;; esac
    done
    return 1
}

tests="valgrind_pack_cloud_without_normals valgrind_pack_textured_mesh valgrind_pack_info
valgrind_render_loads_a_look_paints_and_saves valgrind_imgdiff
valgrind_error_paths_free_everything valgrind_render_bundled_face"
if ! command -v valgrind >/dev/null 2>&1; then
    for t in $tests; do selected "$t" && echo "skip - $t: valgrind not installed (Debian: valgrind)"; done
    exit 0
fi

# memcheck NAME WANT_RC CMD...: runs CMD under memcheck; passes when CMD exits WANT_RC (valgrind's own
# error exit is 99, never a program's) and valgrind reports no error and no leak.
memcheck() {
    name=$1 want=$2
    shift 2
    selected "$name" || return 0
    log="$out/$name.log"
    valgrind --quiet --keep-debuginfo=yes --suppressions=tests/valgrind.supp --leak-check=full \
        --show-leak-kinds=definite,indirect,possible --errors-for-leak-kinds=definite,indirect,possible \
        --error-exitcode=99 --num-callers=30 --log-file="$log" "$@" >"$tmp/stdout" 2>"$tmp/stderr"
    rc=$?
    if [ "$rc" -eq 99 ] || grep -q "==[0-9]*== [A-Z]" "$log"; then
        echo "FAIL - $name: valgrind: $(grep -m1 -E '==[0-9]+== [A-Z]' "$log" | sed 's/^==[0-9]*== //') (log: $log)"
    elif [ "$rc" -ne "$want" ]; then
        echo "FAIL - $name: exit $rc, wanted $want: $(head -c 300 "$tmp/stderr")"
    else
        echo "ok - $name"
    fi
}

for p in "$rouge" "$pack" "$imgdiff"; do
    why=""
    [ -x "$p" ] || why="$p not built"
    # `make asan` runs this suite too: valgrind cannot run AddressSanitizer binaries (ASan checks them).
    [ -z "$why" ] && grep -q __asan_init "$p" && why="$p is built with AddressSanitizer"
    if [ -n "$why" ]; then
        for t in $tests; do selected "$t" && echo "skip - $t: $why"; done
        exit 0
    fi
done

memcheck valgrind_pack_cloud_without_normals 0 "$pack" $fx/ply/points_no_normals.ply -o "$tmp/cloud.rsf" -q
# The mesh has no face to find: the frame is given (--up/--forward), since the search for a face in every
# orientation cost ~55 of this script's CPU-s under valgrind for nothing; the cloud above still runs that
# search under memcheck.
memcheck valgrind_pack_textured_mesh 0 "$pack" $fx/ply/mesh_st.ply --points 3000 --up +y --forward +z --texture $fx/image/a_8x8.png \
    --normal-map $fx/image/c_4x4.png --specular-map $fx/image/c_4x4.png --region-map $fx/image/a_8x8.png \
    --preview "$tmp/preview.png" -o "$tmp/mesh.rsf"

# The face for the renders, converted natively (the conversion was checked above), and a short stroke
# (three samples: every stamp renders the ID buffer, which is slow under valgrind).
"$pack" $fx/ply/mesh_st.ply --points 3000 --up +y --forward +z --texture $fx/image/a_8x8.png -o "$tmp/face.rsf" -q 2>/dev/null
printf 'rouge-strokes 1\nview yaw=0 pitch=0 zoom=1 fov=30 size=48x48\n%s\ncosmetic blush\nstroke\n%s\nend\n' \
    "brush size=0.3 opacity=0.8 pressure=floor mirror=1 eraser=0" \
    "s 0.00 20.0 24.0 0.5
s 0.02 24.0 24.0 0.7
s 0.04 28.0 24.0 0.9" >"$tmp/short.strokes"
memcheck valgrind_pack_info 0 "$pack" --info "$tmp/face.rsf"
# One render does it all: load a look made natively, replay the stroke on top (ID-buffer picks), save the
# look, mobile pipeline. The first look is made natively as any test renders, with Mesa's shader cache and
# optimiser: its shaders come from the run's cache or go into it for the others (with the cache off, as
# below, it compiled every shader for itself: ~2 CPU-s).
(
    unset MESA_SHADER_CACHE_DISABLE MESA_GLSL_CACHE_DISABLE GALLIVM_PERF
    "$rouge" render "$tmp/face.rsf" --size 48x48 --strokes "$tmp/short.strokes" --save-look "$tmp/first.look" \
        -o "$tmp/first.png" >/dev/null 2>&1
)
set -- "$rouge" render "$tmp/face.rsf" --size 48x48 --pipeline mobile --look "$tmp/first.look" \
    --strokes "$tmp/short.strokes" --save-look "$tmp/second.look" -o "$tmp/painted.png"
if selected valgrind_render_loads_a_look_paints_and_saves; then
    # About half of this render's time under memcheck was llvmpipe compiling its shaders (LLVM itself
    # run under memcheck, ~50 CPU-s). The same command runs first under valgrind's no-op tool (a few
    # times native speed, not ~40) with a private Mesa shader cache, and memcheck reads every program
    # back from it: Mesa's cache is keyed by the CPU valgrind shows, so only a run under valgrind can fill
    # it, and one of the same command finds every program memcheck's run will ask for, so memcheck never
    # writes an entry (that path trips on Mesa's padding bytes; see above). rouge's code runs the same.
    (
        unset MESA_SHADER_CACHE_DISABLE MESA_GLSL_CACHE_DISABLE
        export MESA_SHADER_CACHE_DIR="$tmp/shader-cache"
        valgrind --tool=none --quiet --log-file="$out/warm-shaders.log" "$@" >/dev/null 2>&1
        memcheck valgrind_render_loads_a_look_paints_and_saves 0 "$@"
    )
fi
memcheck valgrind_imgdiff 0 "$imgdiff" $fx/image/a_8x8.png $fx/image/b_8x8_one_pixel_rgba.png --diff "$tmp/d.png"

# Error paths: every early return frees what it allocated.
if selected valgrind_error_paths_free_everything; then
    head -c 650 $fx/rsf/tiny_v1.rsf >"$tmp/cut.rsf"
    fail=""
    for c in "1|$rouge render $tmp/cut.rsf -o $tmp/x.png" "1|$rouge render $fx/rsf/bad_crc.rsf -o $tmp/x.png" \
        "1|$pack $fx/ply/bad_face_index.ply -o $tmp/x.rsf" "1|$pack $fx/bad/ply_binary_short_body.ply -o $tmp/x.rsf" \
        "1|$pack $fx/ply/mesh_st.ply --texture $fx/bad/png_truncated.png -o $tmp/x.rsf" \
        "1|$rouge render $tmp/face.rsf --size 32x32 --look $fx/bad/look_nan_stamp.look -o $tmp/x.png" \
        "1|$pack --info $fx/bad/rsf_region_m_nan.rsf" \
        "2|$imgdiff $fx/image/a_8x8.png $fx/bad/png_huge_dimensions.png"; do
        want=${c%%|*} cmd=${c#*|}
        # shellcheck disable=SC2086
        r=$(memcheck valgrind_error_paths_free_everything "$want" $cmd)
        case $r in ok*) ;; *) fail="${fail:-$r ($cmd)}" ;; esac
    done
    if [ -z "$fail" ]; then echo "ok - valgrind_error_paths_free_everything"; else echo "$fail"; fi
fi

if [ "${RS_VALGRIND_FACE:-0}" = 1 ]; then
    memcheck valgrind_render_bundled_face 0 "$rouge" render assets/face.rsf --size 32x32 --max-splats 2000 \
        -o "$tmp/face.png"
elif selected valgrind_render_bundled_face; then
    echo "skip - valgrind_render_bundled_face: ~90 s; make test-full runs it (RS_VALGRIND_FACE=1)"
fi
exit 0
