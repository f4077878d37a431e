#!/bin/sh
# make figures: renders the paper's Figures 7-12 on the bundled head into docs/figures/*.png with
# `rouge render` (reference pipeline, full mode, all splats, 512x512), replaying the stroke files in
# tools/figures/ through the same ID-buffer picking as the viewer. docs/figures/README.md shows them.
#
# Usage: sh tools/figures.sh [BUILD_DIR] [FIGURE...]   (`make figures` does; paths are relative to the
#   repository root, wherever it runs from). FIGURE: 7 8 9 10 11 12 13 (default: all). FIGURES_OUT
#   overrides the output folder (default docs/figures), FIGURES_FACE the face (default
#   assets/face.rsf). Two to four minutes on llvmpipe.
set -u
build=${1:-build}
[ $# -gt 0 ] && shift
cd "$(dirname "$0")/.." || exit 1
rouge="$build/rouge"
face=${FIGURES_FACE:-assets/face.rsf}
out=${FIGURES_OUT:-docs/figures}
strokes=tools/figures
[ -x "$rouge" ] || { echo "figures: $rouge not built (run 'make figures' or 'make BUILD=$build all')" >&2; exit 1; }
[ -f "$face" ] || { echo "figures: no $face" >&2; exit 1; }
mkdir -p "$out"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
status=0

# One view for every figure: a slight three-quarter view of the subject's left side from a little below
# (the scan's head tilts back). The stroke files record the same view (their pixel coordinates refer to it).
# Two lightings: the paper's (one key light from above on the same side, so the cheek the camera sees most
# is lit, a soft fill from the other side, no tone curve) for the colour figures 8 and 9 that reproduce
# it; and the studio environment turned so its softbox key comes from the same side (yaw 30) for the
# figures about reflectance (7, 10, 11, 12), where one lamp makes the differences invisible (issue 12).
# Fig. 13 shows one look under every environment.
view="--size 512x512 --yaw 15 --pitch -4 --zoom 1.1 --fov 30"
paper="--env paper --light-yaw 30 --light-pitch 15 --fill-yaw -45 --fill-pitch 0 --fill-intensity 0.35"
studio="--env studio --env-rotate 65"
light=$paper

# render NAME [rouge options...]: docs/figures/NAME.png
render() {
    name=$1
    shift
    # shellcheck disable=SC2086  # $view and $light are option lists
    if "$rouge" render "$face" $view $light "$@" -o "$out/$name.png" >"$tmp/log" 2>&1; then
        echo "figures: $out/$name.png"
    else
        echo "figures: $name failed: $(cat "$tmp/log")" >&2
        status=1
    fi
}

# painted NAME [rouge options...]: NAME.png in full mode and NAME_specular.png, the specular image alone
# (skin, clear coat and flakes; exposure 3: skin reflects only about 3 % at normal incidence), from the
# same makeup layer.
painted() {
    name=$1
    shift
    render "$name" "$@" --save-look "$tmp/$name.look"
    [ -f "$tmp/$name.look" ] && render "${name}_specular" --look "$tmp/$name.look" --mode specular --exposure 3
}

want() {
    [ -z "$figures" ] && return 0
    for f in $figures; do [ "$f" = "$1" ] && return 0; done
    return 1
}
figures="$*"

# Fig. 7: no lighting / subsurface only / subsurface + specular (no makeup).
light=$studio
if want 7; then
    render fig07_albedo --mode albedo
    render fig07_diffuse --mode diffuse
    render fig07_full --mode full
fi

# Fig. 8: the same blush sweep with brush sizes 0.1, 0.2, 0.3.
light=$paper
if want 8; then
    for s in 10 20 30; do render "fig08_size$s" --strokes "$strokes/fig08_size$s.strokes"; done
fi

# Fig. 9: foundation shades 1, 2, 3 over the same part of the face.
if want 9; then
    for k in 1 2 3; do render "fig09_shade$k" --strokes "$strokes/fig09_shade$k.strokes"; done
fi

# Fig. 10: one colour with a different finish on forehead (matte), cheeks (satin) and lips (gloss); and the
# bare face's specular, its own per-region reflectance.
light=$studio
if want 10; then
    painted fig10_same_colour --strokes "$strokes/fig10_same_colour.strokes"
    render fig10_bare_specular --mode specular --exposure 3
fi

# Fig. 11: a cream blush with rho_s 0.170, 0.240, 0.310 on the lit cheek.
if want 11; then
    for r in 170 240 310; do painted "fig11_rho$r" --strokes "$strokes/fig11_rho$r.strokes"; done
fi

# Fig. 12: the base state (skin finish m 0.23, rho_s 0.18), then two made-up faces painted over it:
# (a) matte base (foundation + powder) + colourless lip gloss, (b) matte pink lips, powdered cheeks,
# brown eyeshadow.
if want 12; then
    painted fig12_base --strokes "$strokes/fig12_base.strokes"
    if [ -f "$tmp/fig12_base.look" ]; then
        painted fig12_matte_gloss --look "$tmp/fig12_base.look" --strokes "$strokes/fig12_matte_gloss.strokes"
        painted fig12_pink_lips --look "$tmp/fig12_base.look" --strokes "$strokes/fig12_pink_lips.strokes"
    fi
fi

# Fig. 13: one look (fig. 12's matte base, colourless lip gloss) under every lighting environment, each
# unturned (its key light front-left) so they compare like for like.
if want 13; then
    light=$studio
    render fig13_look --strokes "$strokes/fig12_base.strokes" --save-look "$tmp/fig13_base.look"
    if [ -f "$tmp/fig13_base.look" ]; then
        render fig13_look --look "$tmp/fig13_base.look" --strokes "$strokes/fig12_matte_gloss.strokes" \
            --save-look "$tmp/fig13.look"
        for e in studio daylight office sunset paper; do
            light="--env $e"
            render "fig13_$e" --look "$tmp/fig13.look"
        done
    fi
    rm -f "$out/fig13_look.png"
fi
exit $status
