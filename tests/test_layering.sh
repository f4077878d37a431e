#!/bin/sh
# test_layering.sh — src/render/'s dependencies run one way (STYLE.md rule 15), read from the built objects:
#   render.o (the orchestrator) -> the stages (every other render_*.o) -> the kit (render_kit.o, render_view.o,
#   profile.o). A stage calls nothing defined in render.o and no sibling's pass (a sibling's *_uniforms
#   lookup, and its *_unbind after the pass, are allowed); the kit calls nothing defined in render.o or in a stage.
# Usage: sh tests/test_layering.sh BUILD_DIR [NAME_FILTER...]   (run from the repository root)
build=${1:-build}
[ $# -gt 0 ] && shift
filters="$*"
obj="$build/obj/src/render"
kit="render_kit.o render_view.o profile.o"
status=0

selected() {
    [ -z "$filters" ] && return 0
    for f in $filters; do
        case "$1" in *"$f"*) return 0 ;; esac
    done
    return 1
}

# defined FILE / undefined FILE: the rs_ functions an object defines / calls, one a line (nm once per object).
syms=$(mktemp -d)
trap 'rm -rf "$syms"' EXIT
defined() {
    [ -f "$syms/${1##*/}.T" ] || nm "$1" | awk '$2 == "T" && $3 ~ /^rs_/ { print $3 }' >"$syms/${1##*/}.T"
    cat "$syms/${1##*/}.T"
}
undefined() {
    [ -f "$syms/${1##*/}.U" ] || nm "$1" | awk '$1 == "U" && $2 ~ /^rs_/ { print $2 }' >"$syms/${1##*/}.U"
    cat "$syms/${1##*/}.U"
}

if ! command -v nm >/dev/null 2>&1; then
    echo "skip - layering: nm not installed"
    exit 0
fi
if [ ! -f "$obj/render.o" ]; then
    echo "FAIL - layering_objects_built: $obj/render.o missing (make BUILD=$build all)"
    exit 1
fi
stages=""
for o in "$obj"/render_*.o; do
    case " $kit " in *" ${o##*/} "*) continue ;; esac
    stages="$stages $o"
done
orch=$(defined "$obj/render.o")

# report NAME WHY: ok when WHY is empty.
report() {
    if [ -z "$2" ]; then
        echo "ok - $1"
    else
        echo "FAIL - $1: $2"
        status=1
    fi
}

name=layering_finds_the_orchestrator_and_the_stages
if selected $name; then
    why=
    echo "$orch" | grep -qx rs_render_frame || why="render.o does not define rs_render_frame"
    for s in shadow visibility attributes composite; do
        found=0
        for o in $stages; do defined "$o" | grep -qx "rs_render_$s" && found=1; done
        [ $found -eq 1 ] || why="$why no stage object defines rs_render_$s;"
    done
    report $name "$why"
fi

name=layering_no_stage_calls_into_render_c
if selected $name; then
    why=
    for o in $stages; do
        for f in $(undefined "$o"); do
            grep -qx "$f" "$syms/render.o.T" && why="$why ${o##*/} calls $f (render.c);"
        done
    done
    report $name "$why"
fi

name=layering_no_stage_runs_a_sibling_pass
if selected $name; then
    why=
    for o in $stages; do
        for s in $stages; do
            [ "$s" = "$o" ] && continue
            for f in $(undefined "$o"); do
                case "$f" in *_uniforms|*_unbind) continue ;; esac
                defined "$s" | grep -qx "$f" && why="$why ${o##*/} calls $f (${s##*/});"
            done
        done
    done
    report $name "$why"
fi

name=layering_kit_calls_nothing_above_it
if selected $name; then
    why=
    for k in $kit; do
        [ -f "$obj/$k" ] || { why="$why $k missing;"; continue; }
        for f in $(undefined "$obj/$k"); do
            grep -qx "$f" "$syms/render.o.T" && why="$why $k calls $f (render.c);"
            for s in $stages; do defined "$s" | grep -qx "$f" && why="$why $k calls $f (${s##*/});"; done
        done
    done
    report $name "$why"
fi

exit $status
