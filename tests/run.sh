#!/bin/sh
# Runs every test program (build/tests/test_*) and script (tests/test_*.sh) and sums up their
# "ok"/"FAIL"/"skip" lines into the closing "N passed, N failed, N skipped" line.
# Tests run RS_TEST_JOBS at a time (default: the number of cores), the longest first so the short ones
# fill in beside them (a program's slowest checks may run as jobs of their own: $split below); each one's
# output is printed whole, in name order, once all have run, and the run ends with the CPU seconds spent.
# Usage: tests/run.sh [BUILD_DIR] [NAME_FILTER...]
build=${1:-build}
[ $# -gt 0 ] && shift
logs=$(mktemp -d)
trap 'rm -rf "$logs"' EXIT
export RS_BUILD="$build"
export RS_TEST_OUT="$build/test-out"
mkdir -p "$RS_TEST_OUT"
jobs=${RS_TEST_JOBS:-$(nproc 2>/dev/null || echo 2)}

# Every test shares the pool: none needs an idle machine (test_atomic_save's kill loop counts the kills
# that land inside a save instead of running for a fixed time; it once ran alone after the pool, and so
# waited for the browser test).
# The slow ones first, longest first (CPU seconds of a fresh clone's run, session 5; valgrind runs on one
# core), so that the short ones fill in beside them and both cores finish together; then the rest in name
# order; the browser test last: it overlaps the native tests' last minute, and nothing waits for it.
slow="tests/test_valgrind.sh tests/test_viewer.sh $build/tests/test_edges $build/tests/test_fine_makeup
      $build/tests/test_mobile $build/tests/test_truth $build/tests/test_paint_render $build/tests/test_lighting
      $build/tests/test_render $build/tests/test_env_specular $build/tests/test_incremental $build/tests/test_shadow
      tests/test_robustness.sh"
last="tests/test_web.sh"
# One space between names: the membership tests below match " NAME " (a line break once ran test_edges twice).
slow=$(echo $slow)
all=""
for t in "$build"/tests/test_* tests/test_*.sh; do
    [ -f "$t" ] || continue
    case "$t" in *.d|*.o) continue ;; esac
    all="$all $t"
done
# Programs whose slowest checks run as jobs of their own, beside the rest of the program (the harness's
# "-SUB" leaves them out of it): PROGRAM=SUB,SUB... Only without a name filter.
split="$build/tests/test_mobile=tolerance_at_256,under_environments"
# jobs_of TEST: its jobs, TEST or TEST+ARG+ARG... (the arguments replace the name filter).
jobs_of() {
    t=$1
    shift
    for s in $split; do
        [ $# -eq 0 ] && [ "${s%%=*}" = "$t" ] || continue
        rest=$t
        for sub in $(echo "${s#*=}" | tr , ' '); do echo "$t+$sub"; rest="$rest+-$sub"; done
        echo "$rest"
        return
    done
    echo "$t"
}
order=""
for t in $slow; do case " $all " in *" $t "*) order="$order $(jobs_of "$t" "$@")" ;; esac; done
for t in $all; do case " $slow $last " in *" $t "*) ;; *) order="$order $(jobs_of "$t" "$@")" ;; esac; done
for t in $last; do case " $all " in *" $t "*) order="$order $(jobs_of "$t" "$@")" ;; esac; done

# One test: its output to LOGS/NAME.log, closed by a line "# TEST: W s wall, C s CPU" (C: user + system
# seconds of everything it waited for, from the shell's `times`), and its exit status to LOGS/NAME.rc.
export logs build
export RS_FILTERS="$*"
one='t={}; n=$(echo "$t" | tr /+ __) p=${t%%+*} args=$RS_FILTERS
    case "$t" in *+*) args=$(echo "${t#*+}" | tr + " ") ;; esac
    start=$(date +%s.%N)
    case "$p" in
        *.sh) sh "$p" "$build" $args ;;
        *) "$p" $args ;;
    esac > "$logs/$n.log" 2>&1
    echo $? > "$logs/$n.rc"
    end=$(date +%s.%N)
    echo "$end" > "$logs/$n.end"
    times > "$logs/$n.times"
    awk -v t="$t" -v s="$start" -v e="$end" "NR == 2 { split(\$0, f, /[ms]+/)
        printf \"# %s: %.1f s wall, %.1f s CPU\\n\", t, e - s, f[1] * 60 + f[2] + f[3] * 60 + f[4] }" \
        "$logs/$n.times" >> "$logs/$n.log"'
run_start=$(date +%s.%N)
# shellcheck disable=SC2086
printf '%s\n' $order | xargs -P "$jobs" -I{} sh -c "$one"

status=0
for t in $(for a in $all; do jobs_of "$a" "$@"; done); do
    n=$(echo "$t" | tr /+ __)
    echo "# $t"
    cat "$logs/$n.log"
    rc=$(cat "$logs/$n.rc" 2>/dev/null || echo 1)
    if [ "$rc" -ne 0 ]; then
        status=1
        # A crash or an error exit without a FAIL line still counts as a failure.
        grep -q '^FAIL - ' "$logs/$n.log" || { echo "FAIL - $t: exited with status $rc"; echo "FAIL - $t" >> "$logs/$n.log"; }
    fi
done
p=$(cat "$logs"/*.log | grep -c '^ok - ')
f=$(cat "$logs"/*.log | grep -c '^FAIL - ')
s=$(cat "$logs"/*.log | grep -c '^skip - ')
[ "$f" -gt 0 ] && status=1
# What the time went to: the CPU seconds of all tests (what the cores must share) and the slowest ones.
sed -n 's/^# \(.*\): \([0-9.]*\) s wall, \([0-9.]*\) s CPU$/\3 \2 \1/p' "$logs"/*.log | sort -n -r | awk '
    { cpu += $1; if (NR <= 8) top = top sprintf("#   %6.1f s CPU %6.1f s wall  %s\n", $1, $2, $3) }
    END { printf "# %.0f s CPU in all tests; the slowest:\n%s", cpu, top }'
# The native tests' wall time: from the start until the last of them (all but the browser test) ended.
native_end=$(for e in "$logs"/*.end; do case "$e" in *tests_test_web.sh.end) ;; *) cat "$e" ;; esac; done | sort -n | tail -1)
[ -n "$native_end" ] && awk -v s="$run_start" -v e="$native_end" \
    'BEGIN { printf "# native tests (all but tests/test_web.sh): %.1f s wall\n", e - s }'
echo "$p passed, $f failed, $s skipped"  # the last line, for whatever reads the result
exit $status
