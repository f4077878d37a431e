#!/bin/sh
# CLI behaviour of `rouge-env`: the tiny committed fixtures (tests/fixtures/env, make_fixtures.py) convert
# with the planted light found where it was put, the result loads (--info, the run-time loader); the
# blender-data HDRIs convert when installed; truncated, hostile and garbage .hdr/.exr files and bad flags get
# one "rouge-env: ..." line, exit 1 (input) or 2 (usage), and leave no output file (nor a temp file).
build=${1:-build}
env_tool="$build/rouge-env"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fx=tests/fixtures/env
world=/usr/share/blender/datafiles/studiolights/world

if [ ! -x "$env_tool" ]; then echo "FAIL - env_tool: $env_tool not built"; exit 1; fi

# expect NAME WANT_RC PATTERN CMD... : runs CMD, checks the exit code and a one-line stderr matching PATTERN.
expect() {
    name=$1; want=$2; pat=$3; shift 3
    "$@" >"$tmp/out" 2>"$tmp/err"
    rc=$?
    lines=$(wc -l <"$tmp/err")
    if [ "$rc" -ne "$want" ]; then
        echo "FAIL - $name: exit $rc, wanted $want: $(head -c 300 "$tmp/err")"
    elif [ -n "$pat" ] && ! grep -q -- "$pat" "$tmp/err"; then
        echo "FAIL - $name: stderr lacks '$pat': $(head -c 300 "$tmp/err")"
    elif [ "$want" -ne 0 ] && { [ "$lines" -ne 1 ] || ! grep -q '^rouge-env: ' "$tmp/err"; }; then
        echo "FAIL - $name: error is not one 'rouge-env:' line: $(head -c 300 "$tmp/err")"
    else
        echo "ok - $name"
    fi
}
no_file() {
    if [ -e "$2" ] || ls "$2".tmp* >/dev/null 2>&1; then echo "FAIL - $1: left $2 behind"; else echo "ok - $1"; fi
}
# near NAME VALUE WANT TOL: |VALUE - WANT| <= TOL
near() {
    if awk -v v="$2" -v w="$3" -v t="$4" 'BEGIN { d = v - w; if (d < 0) d = -d; exit !(v != "" && d <= t) }'; then
        echo "ok - $1"
    else
        echo "FAIL - $1: got '$2', wanted $3 +- $4"
    fi
}
# The "light at yaw Y pitch P deg" of the tool's summary line.
light_yaw() { sed -n 's/.*light at yaw \([-0-9.]*\) pitch.*/\1/p' "$1"; }
light_pitch() { sed -n 's/.*light at yaw [-0-9.]* pitch \([-0-9.]*\) deg.*/\1/p' "$1"; }

# ---- the fixtures: a 6-degree sun at u 0.3, v 0.3 (pitch 36) in a sky ----
for f in tiny.hdr tiny_flat.hdr tiny.exr; do
    n=$(echo "$f" | tr . _)
    expect "env_tool_converts_$n" 0 "" "$env_tool" "$fx/$f" -o "$tmp/$n.rse" --name tiny --key-yaw 20 \
        --notes "test fixture, CC0" --preview "$tmp/p.png"
    near "env_tool_${n}_light_pitch" "$(light_pitch "$tmp/out")" 36 3.5
    near "env_tool_${n}_light_turned_to_key_yaw" "$(light_yaw "$tmp/out")" 20 3
    expect "env_tool_${n}_output_loads" 0 "" "$env_tool" --info "$tmp/$n.rse"
    if grep -q "^name: tiny" "$tmp/out" && grep -q "levels: 6, level 0 256x128" "$tmp/out" &&
        grep -q "test fixture, CC0" "$tmp/out"; then
        echo "ok - env_tool_${n}_info_shows_name_levels_notes"
    else
        echo "FAIL - env_tool_${n}_info_shows_name_levels_notes: $(head -c 300 "$tmp/out")"
    fi
done
# The same pixels in three encodings give the same environment (texels: the notes name the file).
texels() { tail -c 174724 "$1" | head -c 174720 | cksum; }
if [ "$(texels "$tmp/tiny_hdr.rse")" = "$(texels "$tmp/tiny_flat_hdr.rse")" ]; then
    echo "ok - env_tool_rle_and_flat_hdr_agree"; else echo "FAIL - env_tool_rle_and_flat_hdr_agree: texels differ"; fi
# (half floats round the EXR's pixels: its light may differ in the last bits, its map barely)
if [ -s "$tmp/p.png" ]; then echo "ok - env_tool_preview_written"; else echo "FAIL - env_tool_preview_written"; fi
expect env_tool_light_near 0 "" "$env_tool" "$fx/tiny.hdr" -o "$tmp/n.rse" --name tiny --light-near 0.3,0.3 --key-yaw 0
near env_tool_light_near_finds_the_sun "$(light_pitch "$tmp/out")" 36 3.5

# ---- usage errors: exit 2, one line, no output ----
expect env_tool_help 0 "" "$env_tool" --help
expect env_tool_no_args 2 "needs IN" "$env_tool"
expect env_tool_no_name 2 "needs IN" "$env_tool" "$fx/tiny.hdr" -o "$tmp/u.rse"
expect env_tool_bad_name 2 "--name" "$env_tool" "$fx/tiny.hdr" -o "$tmp/u.rse" --name "Has Space"
expect env_tool_long_name 2 "--name" "$env_tool" "$fx/tiny.hdr" -o "$tmp/u.rse" --name abcdefghijklmnopqrstuvwxyz0123456789
expect env_tool_bad_yaw 2 "--key-yaw" "$env_tool" "$fx/tiny.hdr" -o "$tmp/u.rse" --name t --key-yaw 12x
expect env_tool_huge_yaw 2 "--key-yaw" "$env_tool" "$fx/tiny.hdr" -o "$tmp/u.rse" --name t --key-yaw 1e9
expect env_tool_bad_light_near 2 "--light-near" "$env_tool" "$fx/tiny.hdr" -o "$tmp/u.rse" --name t --light-near 2,0.5
expect env_tool_missing_value 2 "--name needs a value" "$env_tool" "$fx/tiny.hdr" -o "$tmp/u.rse" --name
expect env_tool_unknown_flag 2 "unknown option '--frobnicate'" "$env_tool" "$fx/tiny.hdr" -o "$tmp/u.rse" --name t --frobnicate
expect env_tool_two_inputs 2 "one input" "$env_tool" "$fx/tiny.hdr" "$fx/tiny.exr" -o "$tmp/u.rse" --name t
no_file env_tool_usage_errors_leave_no_output "$tmp/u.rse"

# ---- bad input files: exit 1, one line naming the file, no output ----
expect env_tool_missing_input 1 "none.hdr" "$env_tool" "$tmp/none.hdr" -o "$tmp/b.rse" --name t
expect env_tool_directory_input 1 "not a regular file" "$env_tool" "$fx" -o "$tmp/b.rse" --name t
expect env_tool_truncated_hdr 1 "bad_truncated.hdr: the file ends at row" "$env_tool" "$fx/bad_truncated.hdr" -o "$tmp/b.rse" --name t
expect env_tool_truncated_flat_hdr 1 "truncated" "$env_tool" "$fx/bad_truncated_flat.hdr" -o "$tmp/b.rse" --name t
expect env_tool_huge_hdr 1 "200000x100000 pixels: an environment map is at most 8192x4096" "$env_tool" "$fx/bad_huge.hdr" -o "$tmp/b.rse" --name t
expect env_tool_garbage_hdr 1 "bad_garbage.hdr" "$env_tool" "$fx/bad_garbage.hdr" -o "$tmp/b.rse" --name t
expect env_tool_not_2to1 1 "64x64 is not a latitude-longitude map" "$env_tool" "$fx/bad_ratio.hdr" -o "$tmp/b.rse" --name t
expect env_tool_not_hdr 1 "neither OpenEXR nor Radiance" "$env_tool" "$fx/bad_not_hdr.png" -o "$tmp/b.rse" --name t
expect env_tool_truncated_exr 1 "bad_truncated.exr: OpenEXR:" "$env_tool" "$fx/bad_truncated.exr" -o "$tmp/b.rse" --name t
expect env_tool_huge_exr 1 "too large (max 8192)" "$env_tool" "$fx/bad_huge.exr" -o "$tmp/b.rse" --name t
expect env_tool_garbage_exr 1 "bad_garbage.exr: OpenEXR:" "$env_tool" "$fx/bad_garbage.exr" -o "$tmp/b.rse" --name t
# Captures with no light (the face rendered black, denormals cost 4x the CPU) and infinite values: one line
# naming the input and the problem (tests/support/hostile_models.sh writes them).
. tests/support/hostile_models.sh
hostile_exr "$tmp/all_nan.exr" 0 0 192 127
hostile_exr "$tmp/all_zero.exr" 0 0 0 0
hostile_exr "$tmp/all_negative.exr" 0 0 128 191
hostile_exr "$tmp/all_denormal.exr" 194 22 1 0
hostile_exr "$tmp/inf.exr" 0 0 128 127
expect env_tool_all_nan 1 "all_nan.exr: every value is NaN" "$env_tool" "$tmp/all_nan.exr" -o "$tmp/b.rse" --name t
expect env_tool_all_zero 1 "all_zero.exr: every value is 0 or denormal" "$env_tool" "$tmp/all_zero.exr" -o "$tmp/b.rse" --name t
expect env_tool_all_negative 1 "all_negative.exr: every value is negative" "$env_tool" "$tmp/all_negative.exr" -o "$tmp/b.rse" --name t
expect env_tool_all_denormal 1 "all_denormal.exr: every value is 0 or denormal" "$env_tool" "$tmp/all_denormal.exr" -o "$tmp/b.rse" --name t
expect env_tool_infinite 1 "inf.exr: 1536 of its 1536 values are infinite" "$env_tool" "$tmp/inf.exr" -o "$tmp/b.rse" --name t
no_file env_tool_no_light_leaves_no_output "$tmp/b.rse"
hostile_exr "$tmp/grey.exr" 0 0 128 63
expect env_tool_generated_grey_capture_converts 0 "" "$env_tool" "$tmp/grey.exr" -o "$tmp/grey.rse" --name t
printf '' >"$tmp/empty.exr"
expect env_tool_empty_file 1 "neither OpenEXR nor Radiance" "$env_tool" "$tmp/empty.exr" -o "$tmp/b.rse" --name t
no_file env_tool_bad_inputs_leave_no_output "$tmp/b.rse"
expect env_tool_unwritable_output 1 "" "$env_tool" "$fx/tiny.hdr" -o "$tmp/no/such/dir/c.rse" --name t
expect env_tool_info_of_a_non_rse 1 "tiny.hdr" "$env_tool" --info "$fx/tiny.hdr"

# ---- blender-data's CC0 HDRIs (DWAB-compressed OpenEXR), when installed ----
if [ -f "$world/studio.exr" ]; then
    expect env_tool_blender_studio 0 "" "$env_tool" "$world/studio.exr" -o "$tmp/studio.rse" --name studio
    # The studio's brightest lamp hangs just above the horizon.
    near env_tool_blender_studio_lamp_pitch "$(light_pitch "$tmp/out")" 4 4
    near env_tool_blender_studio_key_yaw "$(light_yaw "$tmp/out")" -35 0.5
    # A DWAB file cut short, and one with a damaged block: refused cleanly (or read, never a crash).
    size=$(wc -c <"$world/studio.exr")
    head -c $((size / 2)) "$world/studio.exr" >"$tmp/cut.exr"
    expect env_tool_blender_truncated 1 "cut.exr: OpenEXR:" "$env_tool" "$tmp/cut.exr" -o "$tmp/d.rse" --name t
    no_file env_tool_blender_truncated_leaves_no_output "$tmp/d.rse"
    cp "$world/studio.exr" "$tmp/damaged.exr"
    printf '\377\377\377\377\377\377\377\377' | dd of="$tmp/damaged.exr" bs=1 seek=$((size / 3)) conv=notrunc 2>/dev/null
    "$env_tool" "$tmp/damaged.exr" -o "$tmp/e.rse" --name t >/dev/null 2>"$tmp/err"
    rc=$?
    if [ $rc -le 1 ] && [ "$(wc -l <"$tmp/err")" -le 1 ]; then echo "ok - env_tool_blender_damaged_block_is_handled (exit $rc)"; else
        echo "FAIL - env_tool_blender_damaged_block_is_handled: exit $rc: $(head -c 300 "$tmp/err")"; fi
else
    echo "skip - env_tool_blender_hdris: $world absent (make deps installs blender-data)"
fi
