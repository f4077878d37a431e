#!/bin/sh
# make run: opens the viewer on the bundled face when there is a display; otherwise renders it
# headlessly to a PNG and says where.
build=${1:-build}
if [ -n "${DISPLAY:-}" ] || [ -n "${WAYLAND_DISPLAY:-}" ]; then
    exec "$build/rouge" view assets/face.rsf
fi
out="$build/face.png"
echo "rouge: no display (DISPLAY/WAYLAND_DISPLAY unset): rendering headlessly"
exec "$build/rouge" render assets/face.rsf -o "$out" --size 768x768 --pipeline mobile
