#!/bin/sh
# CLI behaviour of `rouge`: bad input gets a one-line error, the right exit code, and no output file.
build=${1:-build}
rouge="$build/rouge"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
face=assets/face.rsf

# expect NAME WANT_RC PATTERN CMD... : runs CMD, checks exit code, one-line stderr matching PATTERN.
expect() {
    name=$1; want=$2; pat=$3; shift 3
    "$@" >"$tmp/out" 2>"$tmp/err"
    rc=$?
    lines=$(wc -l <"$tmp/err")
    if [ "$rc" -ne "$want" ]; then
        echo "FAIL - $name: exit $rc, wanted $want: $(head -c 300 "$tmp/err")"
    elif [ -n "$pat" ] && ! grep -q -- "$pat" "$tmp/err"; then
        echo "FAIL - $name: stderr lacks '$pat': $(head -c 300 "$tmp/err")"
    elif [ "$want" -ne 0 ] && [ "$lines" -ne 1 ]; then
        echo "FAIL - $name: error is $lines lines, wanted one: $(head -c 300 "$tmp/err")"
    else
        echo "ok - $name"
    fi
}
no_file() {
    if [ -e "$2" ] || ls "$2".tmp.* >/dev/null 2>&1; then echo "FAIL - $1: left $2 behind"; else echo "ok - $1"; fi
}

expect cli_help_exits_zero 0 "" "$rouge" --help
expect cli_unknown_flag 2 "unknown option '--frobnicate'" "$rouge" render "$face" -o "$tmp/a.png" --frobnicate
expect cli_bad_number 2 "--yaw: expected a number" "$rouge" render "$face" -o "$tmp/a.png" --yaw abc
expect cli_out_of_range 2 "--size" "$rouge" render "$face" -o "$tmp/a.png" --size 0x10
expect cli_bad_mode 2 "--mode: unknown value 'shiny'" "$rouge" render "$face" -o "$tmp/a.png" --mode shiny
expect cli_missing_value 2 "--zoom needs a value" "$rouge" render "$face" -o "$tmp/a.png" --zoom
expect cli_no_output 2 "no output" "$rouge" render "$face"
expect cli_missing_face 1 "cannot open" "$rouge" render "$tmp/none.rsf" -o "$tmp/b.png"
no_file cli_missing_face_leaves_no_output "$tmp/b.png"
expect cli_directory_as_face 1 "not a regular file" "$rouge" render "$tmp" -o "$tmp/c.png"
no_file cli_directory_leaves_no_output "$tmp/c.png"
expect cli_dev_zero_as_face 1 "not a regular file" "$rouge" render /dev/zero -o "$tmp/c.png"
head -c 1000 "$face" >"$tmp/trunc.rsf"
expect cli_truncated_face 1 "trunc.rsf" "$rouge" render "$tmp/trunc.rsf" -o "$tmp/d.png"
no_file cli_truncated_leaves_no_output "$tmp/d.png"
expect cli_unwritable_output 1 "cannot write" "$rouge" render "$face" -o "$tmp/no/such/dir/e.png" --size 32x32 --max-splats 2000
# A special file as output is refused, never replaced (as root, `-o /dev/null` would otherwise be).
mkfifo "$tmp/fifo"
expect cli_fifo_as_output 1 "not a regular file" "$rouge" render "$face" -o "$tmp/fifo" --size 32x32 --max-splats 2000
if [ -p "$tmp/fifo" ]; then echo "ok - cli_fifo_output_is_left_alone"; else echo "FAIL - cli_fifo_output_is_left_alone: replaced"; fi
# No GLES 3: point glvnd at no EGL vendor at all.
expect cli_no_gles3_is_one_clear_line 1 "no GLES 3 context" \
    env __EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent.json "$rouge" render "$face" -o "$tmp/f.png" --size 32x32
no_file cli_no_gles3_leaves_no_output "$tmp/f.png"
expect cli_render_small 0 "" "$rouge" render "$face" -o "$tmp/g.png" --size 64x64 --max-splats 5000
if [ -s "$tmp/g.png" ]; then echo "ok - cli_render_writes_png"; else echo "FAIL - cli_render_writes_png: no file"; fi
