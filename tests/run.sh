#!/bin/sh
# Runs every test program (build/tests/test_*) and script (tests/test_*.sh) and sums up their
# "ok"/"FAIL"/"skip" lines into the closing "N passed, N failed, N skipped" line.
# Usage: tests/run.sh [BUILD_DIR] [NAME_FILTER...]
build=${1:-build}
[ $# -gt 0 ] && shift
log=$(mktemp)
trap 'rm -f "$log"' EXIT
status=0
export RS_BUILD="$build"
export RS_TEST_OUT="$build/test-out"
mkdir -p "$RS_TEST_OUT"
for t in "$build"/tests/test_* tests/test_*.sh; do
    [ -f "$t" ] || continue
    case "$t" in *.d|*.o) continue ;; esac
    echo "# $t"
    case "$t" in
        *.sh) sh "$t" "$build" "$@" ;;
        *) "$t" "$@" ;;
    esac > "$log.one" 2>&1
    rc=$?
    cat "$log.one"
    cat "$log.one" >> "$log"
    if [ $rc -ne 0 ]; then
        status=1
        # A crash or an error exit without a FAIL line still counts as a failure.
        grep -q '^FAIL - ' "$log.one" || { echo "FAIL - $t: exited with status $rc"; echo "FAIL - $t" >> "$log"; }
    fi
done
rm -f "$log.one"
p=$(grep -c '^ok - ' "$log")
f=$(grep -c '^FAIL - ' "$log")
s=$(grep -c '^skip - ' "$log")
[ "$f" -gt 0 ] && status=1
echo "$p passed, $f failed, $s skipped"
exit $status
