#!/bin/sh
# test_imgdiff.sh — rouge-imgdiff's output lines and exit status (0 ok, 1 tolerance not met, 2 bad input).
# Usage: sh tests/test_imgdiff.sh BUILD_DIR [NAME_FILTER...]   (run from the repository root)
build=${1:-build}
[ $# -gt 0 ] && shift
filters="$*"
bin="$build/rouge-imgdiff"
fx=tests/fixtures/image
out="${RS_TEST_OUT:-$build/test-out}"
mkdir -p "$out"
status=0

selected() {
    [ -z "$filters" ] && return 0
    for f in $filters; do
        case "$1" in *"$f"*) return 0 ;; esac
    done
    return 1
}

# run ARGS...: runs the tool, leaving stdout/stderr in $out/imgdiff.{out,err} and the status in $rc.
run() {
    "$bin" "$@" >"$out/imgdiff.out" 2>"$out/imgdiff.err"
    rc=$?
}

# has_line TEXT: stdout has exactly this line.
has_line() {
    grep -qxF "$1" "$out/imgdiff.out"
}

# Each test sets $why on the first failed check; report prints the verdict.
check() {
    [ -n "$why" ] && return
    eval "$1" || why="$2 (exit $rc; stdout: $(tr '\n' '|' <"$out/imgdiff.out"); stderr: $(cat "$out/imgdiff.err"))"
}

report() {
    if [ -z "$why" ]; then
        echo "ok - $1"
    else
        echo "FAIL - $1: $why"
        status=1
    fi
}

if [ ! -x "$bin" ]; then
    echo "FAIL - imgdiff_is_built: $bin missing (make BUILD=$build all)"
    exit 1
fi

name=imgdiff_identical_images_print_infinite_psnr_and_exit_0
if selected $name; then
    why=
    run "$fx/a_8x8.png" "$fx/a_8x8.png"
    check '[ $rc -eq 0 ]' "exit status"
    check 'has_line "psnr_db inf"' "psnr line"
    check 'has_line "ssim 1.000000"' "ssim line"
    check 'has_line "max_abs 0"' "max_abs line"
    check 'has_line "mean_abs 0.0000"' "mean_abs line"
    check 'has_line "delta_e 0.0000"' "delta_e line"
    check 'has_line "frac_over 0.000000 (threshold 8)"' "frac_over line"
    check '[ $(wc -l <"$out/imgdiff.out") -eq 6 ]' "not exactly six lines"
    check '[ ! -s "$out/imgdiff.err" ]' "stderr not empty"
    report $name
fi

name=imgdiff_one_changed_pixel_gives_known_metrics_and_ignores_alpha
if selected $name; then
    why=
    # b is a with one red sample +20, stored as RGBA: 1 of 64 pixels over the threshold.
    run "$fx/a_8x8.png" "$fx/b_8x8_one_pixel_rgba.png"
    check '[ $rc -eq 0 ]' "exit status"
    check 'has_line "psnr_db 44.94"' "psnr should be 10 log10(255^2 * 192 / 400) = 44.94"
    check 'has_line "max_abs 20"' "max_abs line"
    check 'has_line "mean_abs 0.1042"' "mean_abs should be 20 / 192"
    check 'has_line "frac_over 0.015625 (threshold 8)"' "frac_over should be 1/64"
    check 'grep -q "^ssim 0\.99" "$out/imgdiff.out"' "ssim line"
    check 'grep -q "^delta_e 0\.0[0-9]*[1-9]" "$out/imgdiff.out"' "delta_e line"
    report $name
fi

name=imgdiff_threshold_option_feeds_frac_over
if selected $name; then
    why=
    run "$fx/a_8x8.png" "$fx/b_8x8_one_pixel_rgba.png" --threshold 20
    check '[ $rc -eq 0 ]' "exit status"
    check 'has_line "frac_over 0.000000 (threshold 20)"' "a difference equal to the threshold counted"
    run --threshold 19 "$fx/a_8x8.png" "$fx/b_8x8_one_pixel_rgba.png"
    check 'has_line "frac_over 0.015625 (threshold 19)"' "threshold 19 (option first)"
    report $name
fi

name=imgdiff_tolerances_set_exit_status_1
if selected $name; then
    why=
    run "$fx/a_8x8.png" "$fx/b_8x8_one_pixel_rgba.png" --max-frac 0.01
    check '[ $rc -eq 1 ]' "--max-frac 0.01 should fail"
    check 'has_line "max_abs 20"' "metrics not printed on a tolerance failure"
    check 'grep -q "^rouge-imgdiff: frac_over" "$out/imgdiff.err"' "no reason on stderr"
    run "$fx/a_8x8.png" "$fx/b_8x8_one_pixel_rgba.png" --max-frac 0.02
    check '[ $rc -eq 0 ]' "--max-frac 0.02 should pass"
    run "$fx/a_8x8.png" "$fx/b_8x8_one_pixel_rgba.png" --min-psnr 50
    check '[ $rc -eq 1 ]' "--min-psnr 50 should fail"
    run "$fx/a_8x8.png" "$fx/b_8x8_one_pixel_rgba.png" --min-psnr 40 --max-frac 0.02
    check '[ $rc -eq 0 ]' "--min-psnr 40 --max-frac 0.02 should pass"
    run "$fx/a_8x8.png" "$fx/a_8x8.png" --min-psnr 1000 --max-frac 0
    check '[ $rc -eq 0 ]' "identical images should meet any tolerance"
    report $name
fi

name=imgdiff_diff_option_writes_a_readable_png
if selected $name; then
    why=
    rm -f "$out/imgdiff_diff.png"
    run "$fx/a_8x8.png" "$fx/b_8x8_one_pixel_rgba.png" --diff "$out/imgdiff_diff.png"
    check '[ $rc -eq 0 ] && [ -f "$out/imgdiff_diff.png" ]' "diff not written"
    # The diff is black but for one pixel whose red is 4 x 20 = 80: compared with itself it is identical,
    # and it is 8x8 like its inputs.
    run "$out/imgdiff_diff.png" "$out/imgdiff_diff.png"
    check '[ $rc -eq 0 ] && has_line "psnr_db inf"' "diff unreadable"
    run "$out/imgdiff_diff.png" "$fx/a_8x8.png"
    check '[ $rc -eq 0 ]' "diff is not 8x8"
    run "$fx/a_8x8.png" "$fx/a_8x8.png" --diff "$out/no_such_dir/diff.png"
    check '[ $rc -eq 2 ] && grep -q "^rouge-imgdiff: .*no_such_dir/diff.png" "$out/imgdiff.err"' \
        "unwritable --diff should exit 2 naming the path"
    report $name
fi

name=imgdiff_bad_input_exits_2_with_one_error_line
if selected $name; then
    why=
    # Each case: one "rouge-imgdiff: ..." line on stderr, nothing on stdout, exit 2.
    bad() {
        run "$@"
        check '[ $rc -eq 2 ]' "'$*' should exit 2"
        check '[ $(wc -l <"$out/imgdiff.err") -eq 1 ] && grep -q "^rouge-imgdiff: ." "$out/imgdiff.err"' \
            "'$*' should print one error line"
        check '[ ! -s "$out/imgdiff.out" ]' "'$*' printed metrics"
    }
    bad "$fx/a_8x8.png" "$out/no_such_file.png"
    check 'grep -q "no_such_file.png" "$out/imgdiff.err"' "missing file not named"
    bad "$fx/README.md" "$fx/a_8x8.png"
    check 'grep -q "README.md: not a PNG" "$out/imgdiff.err"' "non-PNG not reported"
    bad "$fx" "$fx/a_8x8.png"
    bad "$fx/a_8x8.png" "$fx/c_4x4.png"
    check 'grep -q "8x8 vs 4x4" "$out/imgdiff.err"' "size mismatch should give both sizes"
    bad
    bad "$fx/a_8x8.png"
    bad "$fx/a_8x8.png" "$fx/a_8x8.png" "$fx/a_8x8.png"
    bad "$fx/a_8x8.png" "$fx/a_8x8.png" --bogus
    bad "$fx/a_8x8.png" "$fx/a_8x8.png" --threshold 256
    bad "$fx/a_8x8.png" "$fx/a_8x8.png" --threshold 2.5
    bad "$fx/a_8x8.png" "$fx/a_8x8.png" --max-frac x
    bad "$fx/a_8x8.png" "$fx/a_8x8.png" --min-psnr
    report $name
fi

name=imgdiff_help_prints_usage_and_exits_0
if selected $name; then
    why=
    run --help
    check '[ $rc -eq 0 ]' "exit status"
    check 'grep -q "^usage: rouge-imgdiff" "$out/imgdiff.out"' "no usage line"
    check 'grep -q -- "--max-frac" "$out/imgdiff.out"' "options not listed"
    report $name
fi

exit $status
