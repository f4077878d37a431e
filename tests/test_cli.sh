#!/bin/sh
# CLI behaviour of `rouge`: bad input gets a one-line error, the right exit code, and no output file.
build=${1:-build}
rouge="$build/rouge"
tmp=$(mktemp -d)
trap 'umount "$tmp/full" 2>/dev/null; rm -rf "$tmp"' EXIT
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
# A build directory's rouge finds the tree's face and environments from any working directory.
abs_rouge=$(cd "$(dirname "$rouge")" && pwd)/rouge
# (Renders whose picture is not the point use --mode albedo: no 4096^2 shadow map, ~1 s instead of ~4 s of CPU.)
if (cd "$tmp" && "$abs_rouge" render -o "$tmp/anywhere.png" --size 32x32 --max-splats 2000 --mode albedo >/dev/null 2>"$tmp/err") &&
    [ -s "$tmp/anywhere.png" ]; then echo "ok - cli_default_face_from_any_directory"
else echo "FAIL - cli_default_face_from_any_directory: $(head -c 300 "$tmp/err")"; fi
expect cli_unknown_flag 2 "unknown option '--frobnicate'" "$rouge" render "$face" -o "$tmp/a.png" --frobnicate
expect cli_bad_number 2 "--yaw: expected a number" "$rouge" render "$face" -o "$tmp/a.png" --yaw abc
expect cli_out_of_range 2 "--size" "$rouge" render "$face" -o "$tmp/a.png" --size 0x10
expect cli_bad_mode 2 "--mode: unknown value 'shiny'" "$rouge" render "$face" -o "$tmp/a.png" --mode shiny
expect cli_missing_value 2 "--zoom needs a value" "$rouge" render "$face" -o "$tmp/a.png" --zoom
expect cli_no_output 2 "no output" "$rouge" render "$face"
# Lighting environments (issue 12): --help names them; an unknown one, a missing or corrupt .rse file get one
# line, a non-zero exit and no picture; rouge-env refuses what is not an HDR latitude-longitude map.
if "$rouge" --help 2>&1 | grep -q "studio|daylight|office|sunset|paper"; then echo "ok - cli_help_lists_environments"
else echo "FAIL - cli_help_lists_environments: --help lacks studio|daylight|office|sunset|paper"; fi
expect cli_env_unknown 2 "environment 'nosuch': not one of" "$rouge" render "$face" -o "$tmp/env.png" --env nosuch
no_file cli_env_unknown_leaves_no_output "$tmp/env.png"
expect cli_env_missing_file 1 "missing.rse" "$rouge" render "$face" -o "$tmp/env.png" --env "$tmp/missing.rse"
head -c 5000 assets/env/studio.rse >"$tmp/cut.rse"
expect cli_env_truncated 1 "cut.rse" "$rouge" render "$face" -o "$tmp/env.png" --env "$tmp/cut.rse"
no_file cli_env_truncated_leaves_no_output "$tmp/env.png"
expect cli_env_rotate_range 2 "--env-rotate" "$rouge" render "$face" -o "$tmp/env.png" --env-rotate 1000
printf '#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 99999 +X 199998\n' >"$tmp/huge.hdr"
expect env_tool_huge_claim 1 "huge.hdr" "$build/rouge-env" "$tmp/huge.hdr" -o "$tmp/h.rse" --name huge
no_file env_tool_huge_leaves_no_output "$tmp/h.rse"
printf 'v/1\001garbage' >"$tmp/bad.exr"
expect env_tool_bad_exr 1 "bad.exr" "$build/rouge-env" "$tmp/bad.exr" -o "$tmp/h.rse" --name bad
no_file env_tool_bad_exr_leaves_no_output "$tmp/h.rse"
expect env_tool_no_name 2 "needs IN" "$build/rouge-env" "$tmp/bad.exr" -o "$tmp/h.rse"
expect cli_missing_face 1 "cannot open" "$rouge" render "$tmp/none.rsf" -o "$tmp/b.png"
no_file cli_missing_face_leaves_no_output "$tmp/b.png"
expect cli_directory_as_face 1 "not a regular file" "$rouge" render "$tmp" -o "$tmp/c.png"
no_file cli_directory_leaves_no_output "$tmp/c.png"
expect cli_dev_zero_as_face 1 "not a regular file" "$rouge" render /dev/zero -o "$tmp/c.png"
head -c 1000 "$face" >"$tmp/trunc.rsf"
expect cli_truncated_face 1 "trunc.rsf" "$rouge" render "$tmp/trunc.rsf" -o "$tmp/d.png"
no_file cli_truncated_leaves_no_output "$tmp/d.png"
expect cli_unwritable_output 1 "cannot write" "$rouge" render "$face" -o "$tmp/no/such/dir/e.png" --size 32x32 --max-splats 2000 \
    --mode albedo
# A special file as output is refused, never replaced (as root, `-o /dev/null` would otherwise be).
mkfifo "$tmp/fifo"
expect cli_fifo_as_output 1 "not a regular file" "$rouge" render "$face" -o "$tmp/fifo" --size 32x32 --max-splats 2000 \
    --mode albedo
if [ -p "$tmp/fifo" ]; then echo "ok - cli_fifo_output_is_left_alone"; else echo "FAIL - cli_fifo_output_is_left_alone: replaced"; fi
# A FIFO as any input must be refused at once, not block in open() waiting for a writer (timeout turns a
# hang into exit 124, a failure).
for c in "face|$rouge render $tmp/fifo -o $tmp/h.png" \
    "look|$rouge render $face -o $tmp/h.png --size 32x32 --max-splats 2000 --look $tmp/fifo" \
    "strokes|$rouge render $face -o $tmp/h.png --size 32x32 --max-splats 2000 --strokes $tmp/fifo" \
    "pack_ply|$build/rouge-pack $tmp/fifo -o $tmp/h.rsf" \
    "pack_texture|$build/rouge-pack tests/fixtures/ply/mesh_st.ply --texture $tmp/fifo -o $tmp/h.rsf" \
    "imgdiff|$build/rouge-imgdiff $tmp/fifo tests/fixtures/image/a_8x8.png"; do
    # shellcheck disable=SC2086
    expect "cli_fifo_as_input_${c%%|*}" "$( [ "${c%%|*}" = imgdiff ] && echo 2 || echo 1 )" "not a regular file" \
        timeout 20 ${c#*|}
done
no_file cli_fifo_input_leaves_no_output "$tmp/h.png"
# Integer wrap: sscanf's %d once read 4294967312 as 16.
expect cli_size_does_not_wrap 2 "--size: expected WxH" "$rouge" render "$face" -o "$tmp/i.png" --size 4294967312x16
no_file cli_size_wrap_leaves_no_output "$tmp/i.png"
# Memory: the frame size is bounded by what its render targets cost, said in the error.
expect cli_size_bounded_by_target_memory 1 "needs about 4.7 GiB of render targets" "$rouge" render "$face" -o "$tmp/m.png" --size 8192x8192
no_file cli_size_memory_leaves_no_output "$tmp/m.png"
expect cli_supersample_out_of_range 2 "--supersample: 5 is out of range 1..4" "$rouge" render "$face" -o "$tmp/s.png" --supersample 5
expect cli_supersample_over_max_size 2 "--supersample 3: 4000x4000 would be drawn at 12000x12000" \
    "$rouge" render "$face" -o "$tmp/s.png" --size 4000x4000 --supersample 3 --mode albedo
no_file cli_supersample_over_max_size_leaves_no_output "$tmp/s.png"
expect cli_supersample_bounded_by_target_memory 1 "supersampled 4x: render: 8192x8192 needs about" \
    "$rouge" render "$face" -o "$tmp/s.png" --size 2048x2048 --supersample 4 --mode albedo
no_file cli_supersample_memory_leaves_no_output "$tmp/s.png"
# A supersampled still has the size asked for and the plain render's picture, its edges averaged (not equal).
if "$rouge" render "$face" -o "$tmp/s1.png" --size 48x40 --max-splats 2000 --mode albedo >/dev/null 2>"$tmp/err" &&
    "$rouge" render "$face" -o "$tmp/s2.png" --size 48x40 --max-splats 2000 --mode albedo --supersample 2 >/dev/null 2>>"$tmp/err" &&
    "$build/rouge-imgdiff" "$tmp/s1.png" "$tmp/s2.png" --min-psnr 20 >"$tmp/out" 2>>"$tmp/err" &&
    ! grep -q "psnr_db inf" "$tmp/out"; then echo "ok - cli_supersample_keeps_size_and_picture"
else echo "FAIL - cli_supersample_keeps_size_and_picture: $(head -c 300 "$tmp/err") $(head -c 200 "$tmp/out")"; fi
expect cli_pan_out_of_range 2 "--pan: expected X,Y within -2..2" "$rouge" render "$face" -o "$tmp/p.png" --pan 3,0
expect cli_target_unknown_region_lists_them 2 "no region 'elbow' in this face (it has other|cheek|nose|forehead|lips|eyelid|brow)" \
    "$rouge" render "$face" -o "$tmp/p.png" --size 32x32 --max-splats 2000 --target elbow
no_file cli_target_unknown_leaves_no_output "$tmp/p.png"
expect cli_second_output_refused 2 "-o given twice" "$rouge" render "$face" -o "$tmp/j.png" -o "$tmp/k.png"
cp tests/fixtures/strokes/lips.strokes "$tmp/in.strokes"
expect cli_output_equal_to_input_refused 2 "is an input of this render" \
    "$rouge" render "$face" --strokes "$tmp/in.strokes" -o "$tmp/./in.strokes"
if cmp -s tests/fixtures/strokes/lips.strokes "$tmp/in.strokes"; then echo "ok - cli_output_equal_to_input_keeps_the_input"
else echo "FAIL - cli_output_equal_to_input_keeps_the_input: the stroke file was overwritten"; fi
# A stroke file asking for what the renderer refuses is stopped where it is parsed (file and line named),
# and the failed render leaves neither a saved look nor a PNG behind.
sed 's/fov=[0-9.]*/fov=179/' tests/fixtures/strokes/lips.strokes >"$tmp/wide.strokes"
expect cli_stroke_view_limit_names_file_and_line 1 "wide.strokes: line [0-9]*: view: fov: 179 not in" \
    "$rouge" render "$face" --size 32x32 --max-splats 2000 --strokes "$tmp/wide.strokes" \
    --save-look "$tmp/wide.look" -o "$tmp/wide.png"
no_file cli_failed_render_saves_no_look "$tmp/wide.look"
no_file cli_failed_render_writes_no_png "$tmp/wide.png"
# Terminal injection: a look whose keyword is an escape sequence (clear screen, retitle) is quoted escaped.
printf 'rouge-look 1\n\033[2J\033]0;pwned\007 x\n' >"$tmp/inject.look"
expect cli_error_quotes_file_text_escaped 1 'unknown keyword .\\x1b\[2J' \
    "$rouge" render "$face" --size 32x32 --max-splats 2000 --look "$tmp/inject.look" -o "$tmp/l.png"
if LC_ALL=C grep -q "$(printf '\033')" "$tmp/err"; then echo "FAIL - cli_error_has_no_escape_byte: ESC reached stderr"
else echo "ok - cli_error_has_no_escape_byte"; fi
# A full disk: every writer says "No space left on device" and keeps the old file (a 64 kB tmpfs, filled).
mkdir -p "$tmp/full"
if mount -t tmpfs -o size=64k tmpfs "$tmp/full" 2>/dev/null; then
    for f in o.png o.rsf o.look; do printf 'old %s' "$f" >"$tmp/full/$f"; done
    dd if=/dev/zero of="$tmp/full/filler" bs=1k count=64 >/dev/null 2>&1
    expect cli_full_disk_png 1 "No space left on device" "$rouge" render "$face" -o "$tmp/full/o.png" --size 128x128 --max-splats 2000 \
        --mode albedo
    expect cli_full_disk_rsf 1 "No space left on device" "$build/rouge-pack" tests/fixtures/ply/points_le.ply -o "$tmp/full/o.rsf" -q
    expect cli_full_disk_look 1 "No space left on device" "$rouge" render "$face" -o "$tmp/l.png" --size 32x32 --max-splats 2000 \
        --mode albedo --strokes tests/fixtures/strokes/lips.strokes --save-look "$tmp/full/o.look"
    kept=1
    for f in o.png o.rsf o.look; do [ "$(cat "$tmp/full/$f")" = "old $f" ] || kept=0; done
    left=$(ls "$tmp/full" | grep -c '\.tmp\.')
    if [ $kept = 1 ] && [ "$left" = 0 ]; then echo "ok - cli_full_disk_keeps_old_files"
    else echo "FAIL - cli_full_disk_keeps_old_files: old kept $kept, temp files $left"; fi
    umount "$tmp/full"
else
    echo "skip - cli_full_disk: cannot mount a tmpfs here (needs root)"
fi
# No GLES 3: point glvnd at no EGL vendor at all.
expect cli_no_gles3_is_one_clear_line 1 "no GLES 3 context" \
    env __EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent.json "$rouge" render "$face" -o "$tmp/f.png" --size 32x32
no_file cli_no_gles3_leaves_no_output "$tmp/f.png"
# The mobile pipeline: the reference's fixed setup costs ~3.5 CPU-s at any size, and the default (reference)
# `rouge render` is run by test_install.sh (the installed binary, from another directory) and the render tests.
expect cli_render_small 0 "" "$rouge" render "$face" -o "$tmp/g.png" --size 64x64 --max-splats 5000 --pipeline mobile
if [ -s "$tmp/g.png" ]; then echo "ok - cli_render_writes_png"; else echo "FAIL - cli_render_writes_png: no file"; fi
# The look library (issue 15): save, list, path, rm through `rouge looks`; a name in use is refused unless
# --force; bad names, non-look files and unknown looks get one line and exit 2 (1 for a bad file), and
# nothing lands in the library.
lib="$tmp/lib"
"$rouge" render "$face" -o "$tmp/lk.png" --size 32x32 --max-splats 2000 --mode albedo \
    --strokes tests/fixtures/strokes/lips.strokes --save-look "$tmp/lips.look" >/dev/null 2>&1
expect cli_looks_save 0 "" "$rouge" looks save "Red lips" --look "$tmp/lips.look" --looks "$lib"
if [ -s "$lib/Red lips.look" ] && [ -s "$lib/Red lips.png" ] && cmp -s "$lib/Red lips.look" "$tmp/lips.look"; then
    echo "ok - cli_looks_save_writes_look_and_thumbnail"
else echo "FAIL - cli_looks_save_writes_look_and_thumbnail: $(ls "$lib" 2>&1 | tr '\n' ' ')"; fi
printf 'rouge-look 1\nface height=4.7\n' >"$tmp/empty.look"
expect cli_looks_save_clash_refused 2 "already in the library (--force replaces it)" \
    "$rouge" looks save "Red lips" --look "$tmp/empty.look" --looks "$lib"
if cmp -s "$lib/Red lips.look" "$tmp/lips.look"; then echo "ok - cli_looks_clash_keeps_the_look"
else echo "FAIL - cli_looks_clash_keeps_the_look: the look was replaced"; fi
expect cli_looks_save_force 0 "" "$rouge" looks save "Red lips" --look "$tmp/empty.look" --looks "$lib" --force --no-thumbnail
if cmp -s "$lib/Red lips.look" "$tmp/empty.look" && [ ! -e "$lib/Red lips.png" ]; then echo "ok - cli_looks_force_replaces"
else echo "FAIL - cli_looks_force_replaces: $(ls "$lib" | tr '\n' ' ')"; fi
expect cli_looks_bad_name_slash 2 "look name: '/' not allowed" "$rouge" looks save "a/b" --look "$tmp/lips.look" --looks "$lib"
expect cli_looks_bad_name_dots 2 "look name: '.' not allowed" "$rouge" looks save ".." --look "$tmp/lips.look" --looks "$lib"
expect cli_looks_bad_name_long 2 "at most 40" "$rouge" looks save 12345678901234567890123456789012345678901 \
    --look "$tmp/lips.look" --looks "$lib"
expect cli_looks_bad_name_control 2 "byte 0x1b" "$rouge" looks save "$(printf 'x\033y')" --look "$tmp/lips.look" --looks "$lib"
expect cli_looks_not_a_look 1 "lk.png: line 1: not a look file" "$rouge" looks save pic --look "$tmp/lk.png" --looks "$lib"
expect cli_looks_missing_look_file 1 "cannot open" "$rouge" looks save pic --look "$tmp/none.look" --looks "$lib"
expect cli_looks_unknown_verb 2 "unknown command 'export'" "$rouge" looks export x --looks "$lib"
expect cli_looks_save_needs_look 2 "needs --look FILE" "$rouge" looks save x --looks "$lib"
if [ "$(ls "$lib" | wc -l)" = 1 ]; then echo "ok - cli_looks_refusals_leave_nothing"
else echo "FAIL - cli_looks_refusals_leave_nothing: $(ls -A "$lib" | tr '\n' ' ')"; fi
expect cli_looks_list 0 "" "$rouge" looks list --looks "$lib"
if grep -q "^Red lips " "$tmp/out"; then echo "ok - cli_looks_list_names_the_look"; else echo "FAIL - cli_looks_list_names_the_look: $(cat "$tmp/out")"; fi
expect cli_looks_path 0 "" "$rouge" looks path "Red lips" --looks "$lib"
if [ "$(cat "$tmp/out")" = "$lib/Red lips.look" ]; then echo "ok - cli_looks_path_prints_the_file"
else echo "FAIL - cli_looks_path_prints_the_file: $(cat "$tmp/out")"; fi
expect cli_looks_rm 0 "" "$rouge" looks rm "Red lips" --looks "$lib"
expect cli_looks_rm_unknown 2 "no look named 'Red lips'" "$rouge" looks rm "Red lips" --looks "$lib"
expect cli_looks_list_empty 0 "no looks in" "$rouge" looks list --looks "$lib"
# Issue 23: a --looks path too long for the buffer is refused (it was cut to another folder); escape bytes
# in XDG_DATA_HOME are printed escaped, not sent to the terminal.
long=$(printf '%01100d' 0)
expect cli_looks_long_folder_refused 2 "--looks: the path is 1101 bytes" "$rouge" looks list --looks "/$long"
esc_home="$tmp/x$(printf '\033')]0;owned$(printf '\007')"
mkdir -p "$esc_home"
expect cli_looks_folder_printed_escaped 0 'no looks in .*x\\x1b\]0;owned\\x07/rouge/looks' \
    env XDG_DATA_HOME="$esc_home" "$rouge" looks list
if LC_ALL=C grep -q "$(printf '\033')" "$tmp/err"; then echo "FAIL - cli_looks_folder_no_raw_escape: raw ESC printed"
else echo "ok - cli_looks_folder_no_raw_escape"; fi
