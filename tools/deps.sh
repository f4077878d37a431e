#!/bin/sh
# make deps: checks what rouge needs and installs only what is missing, from Debian's packages.
# Build: pkg-config modules egl glesv2 glfw3 libpng cglm. Run/test: Mesa's EGL + GLES drivers (libegl-mesa0,
# libgl1-mesa-dri: software rendering with llvmpipe when there is no GPU), Xvfb + xauth + xdotool for the
# window test. Scan import (tools/pack): assimp, libjpeg-turbo (JPEG textures), stb_image (BMP/TGA textures). Compact .rsf v2: zstd,
# meshoptimizer (no .pc file in Debian: found by its header). Environment preprocessing (tools/env, tools-time
# only): OpenEXR 3 C API, and blender-data's CC0 HDRIs as the sources of assets/env/. Uses sudo when not root.
set -u
missing=""
need() { missing="$missing $1"; }

command -v cc >/dev/null 2>&1 || need gcc
command -v make >/dev/null 2>&1 || need make
command -v pkg-config >/dev/null 2>&1 || need pkg-config
for pair in egl:libegl-dev glesv2:libgles-dev glfw3:libglfw3-dev libpng:libpng-dev cglm:libcglm-dev \
            assimp:libassimp-dev libjpeg:libjpeg62-turbo-dev stb:libstb-dev libzstd:libzstd-dev OpenEXR:libopenexr-dev; do
    mod=${pair%%:*}
    pkg=${pair#*:}
    pkg-config --exists "$mod" 2>/dev/null || need "$pkg"
done
[ -f /usr/include/meshoptimizer.h ] || need libmeshoptimizer-dev
for pkg in libegl-mesa0 libgl1-mesa-dri xvfb xauth xdotool blender-data; do
    dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q 'install ok installed' || need "$pkg"
done

if [ "${1:-}" = truth ]; then
    for pkg in blender python3-numpy zstd; do
        dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q 'install ok installed' || need "$pkg"
    done
fi

[ -z "$missing" ] && exit 0

if ! command -v apt-get >/dev/null 2>&1; then
    echo "rouge: missing:$missing — install these (Debian package names) with your package manager" >&2
    exit 1
fi
sudo=""
if [ "$(id -u)" != 0 ]; then
    if command -v sudo >/dev/null 2>&1; then sudo=sudo; else
        echo "rouge: missing:$missing — run 'make deps' as root (no sudo here)" >&2
        exit 1
    fi
fi
echo "rouge: installing missing Debian packages:$missing"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq >/dev/null || { echo "rouge: apt-get update failed" >&2; exit 1; }
# shellcheck disable=SC2086
$sudo apt-get install -y -qq --no-install-recommends $missing >/dev/null ||
    { echo "rouge: apt-get install$missing failed" >&2; exit 1; }
echo "rouge: installed:$missing"
