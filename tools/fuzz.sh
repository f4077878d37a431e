#!/bin/sh
# make fuzz: builds a libFuzzer harness for every parser of untrusted input and runs each for a bounded
# time from the committed seed files. Nothing is written under tests/: the corpora libFuzzer grows live in
# a scratch directory, seeded by copying.
#
#   harness                  parser                           seeds
#   tools/fuzz/fuzz_ply.c    rs_ply_load_memory (tools/pack/ply.c)  tests/fixtures/ply
#   tools/fuzz/fuzz_rsf.c    rs_splat_load_memory + rs_splat_loader, v1 and v2 (src/splat)  tests/fixtures/rsf
#   tools/fuzz/fuzz_strokes.c rs_strokes_parse (src/formats/strokes.c) tests/fixtures/strokes
#   tools/fuzz/fuzz_look.c   rs_look_parse + apply (src/formats/look.c) tests/fixtures/looks
#   tools/fuzz/fuzz_convert.c PLY -> convert -> preview -> save/load  tests/fixtures/ply + bad/ply_*
#   tools/fuzz/fuzz_env.c    rs_env_load_memory (src/formats/env.c)  tests/fixtures/env
#   tools/fuzz/fuzz_envmap.c rouge-env's .hdr/.exr readers (tools/env/env_read.c, exr_read.cpp) tests/fixtures/env
#   tools/fuzz/fuzz_import.c assimp import -> pages -> convert (tools/pack/import_assimp.c) tests/fixtures/import
#   tools/fuzz/fuzz_image.c  PNG / JPEG texture decode (tools/pack/image_load.c)  tests/fixtures/image, import
# plus, for each, the inputs kept from earlier crashes: tests/fixtures/bad/fuzz/<name>/ (run first, as
# regression tests; the ordinary test suite also feeds them to the real programs, tests/test_robustness.sh).
#
# Environment: FUZZ_SECONDS (default 60 per harness), FUZZ_TARGETS (default "ply rsf strokes look convert env envmap
# import image"),
# FUZZ_DIR (default build/fuzz), FUZZ_JOBS (parallel harness runs, default 1: the machine may be shared).
# Exit status: 0 no crash, 1 a crash/leak/timeout (the reproducer's path is printed), 2 cannot build.
# Needs clang with libFuzzer and the sanitizer runtimes (Debian: clang, libclang-rt-14-dev).
set -u
cd "$(dirname "$0")/.." || exit 2
seconds=${FUZZ_SECONDS:-60}
targets=${FUZZ_TARGETS:-ply rsf strokes look convert env envmap import image}
dir=${FUZZ_DIR:-build/fuzz}
jobs=${FUZZ_JOBS:-1}
cc=${FUZZ_CC:-clang}

say() { echo "fuzz: $*"; }
die() { echo "fuzz: $*" >&2; exit 2; }

# ---- toolchain check: a libFuzzer program must link ----
command -v "$cc" >/dev/null 2>&1 || die "no '$cc' — install Debian's 'clang' (and 'libclang-rt-14-dev' for libFuzzer)"
mkdir -p "$dir" || die "cannot create $dir"
probe="$dir/probe"
printf '#include <stddef.h>\n#include <stdint.h>\nint LLVMFuzzerTestOneInput(const uint8_t *d, size_t n);\nint LLVMFuzzerTestOneInput(const uint8_t *d, size_t n) { (void)d; (void)n; return 0; }\n' >"$probe.c"
if ! "$cc" -fsanitize=fuzzer,address,undefined "$probe.c" -o "$probe" 2>"$probe.log"; then
    pkg=libclang-rt-14-dev
    ver=$("$cc" -dumpversion 2>/dev/null | cut -d. -f1)
    [ -n "$ver" ] && pkg="libclang-rt-$ver-dev"
    die "'$cc -fsanitize=fuzzer,address,undefined' does not link ($(head -n 1 "$probe.log")): install Debian's '$pkg'"
fi

# ---- build: the libraries with coverage + sanitizers (the project's Makefile, clang, own directory) ----
san='-fsanitize=address,undefined,float-cast-overflow -fno-sanitize-recover=all -fno-omit-frame-pointer'
say "building the libraries with $cc ($san) in $dir/lib"
make --no-print-directory -s BUILD="$dir/lib" CC="$cc" OPT=-O1 \
    EXTRA_CFLAGS="-Wno-unknown-warning-option -fsanitize=fuzzer-no-link $san" \
    "$dir/lib/librouge.a" "$dir/lib/libpack.a" >"$dir/build.log" 2>&1 ||
    { tail -n 20 "$dir/build.log" >&2; die "library build failed (log: $dir/build.log)"; }
pkgs=$(pkg-config --cflags --libs egl glesv2 glfw3 libpng cglm libzstd assimp libjpeg 2>/dev/null)
for t in $targets; do
    src="tools/fuzz/fuzz_$t.c"
    [ -f "$src" ] || die "no harness $src (FUZZ_TARGETS: ply rsf strokes look convert env envmap import image)"
    extra_c="" extra_obj="" link="$cc"
    if [ "$t" = envmap ]; then
        # rouge-env's readers: C parts compiled in, the OpenEXR C++ reader with clang++, linked as C++.
        cxx=${FUZZ_CXX:-clang++}
        # shellcheck disable=SC2046
        "$cxx" -std=c++17 -g -O1 -Wall -Wextra -Werror -fsanitize=fuzzer-no-link $san \
            $(pkg-config --cflags OpenEXR | sed "s/-I/-isystem /g") \
            -c tools/env/exr_read.cpp -o "$dir/exr_read.o" 2>"$dir/fuzz_$t.log" ||
            { cat "$dir/fuzz_$t.log" >&2; die "cannot build tools/env/exr_read.cpp"; }
        extra_c="tools/env/env_read.c tools/env/env_bake.c"
        extra_obj="$dir/exr_read.o $(pkg-config --libs OpenEXR)"
        link="$cxx -x c"
    fi
    # shellcheck disable=SC2086
    $link -std=c11 -g -O1 -Wall -Wextra -Werror -fsanitize=fuzzer $san -Isrc -Itools $(pkg-config --cflags stb) \
        "$src" $extra_c -x none $extra_obj "$dir/lib/libpack.a" "$dir/lib/librouge.a" $pkgs -lm -o "$dir/fuzz_$t" 2>"$dir/fuzz_$t.log" ||
        { cat "$dir/fuzz_$t.log" >&2; die "cannot build $src"; }
done

seeds_of() {
    case $1 in
        ply) echo tests/fixtures/ply ;;
        rsf) echo tests/fixtures/rsf ;;
        strokes) echo tests/fixtures/strokes ;;
        look) echo tests/fixtures/looks ;;
        convert) echo tests/fixtures/ply ;;
        env | envmap) echo tests/fixtures/env ;;
        import) echo tests/fixtures/import ;;
        image) echo tests/fixtures/image ;;
    esac
}

# ---- run ----
# Leaks are errors (ASan's LeakSanitizer at exit of each input); a single input may take at most 10 s
# and 512 MB per allocation: hostile input must not make a parser allocate much beyond its own size.
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
run_one() {
    t=$1
    corpus="$dir/corpus/$t"
    crashes="$dir/crashes/$t"
    # Reproducers of an earlier run move aside, so this run's verdict is its own.
    if [ -n "$(ls "$crashes" 2>/dev/null)" ]; then
        mkdir -p "$dir/crashes-old/$t" && mv "$crashes"/* "$dir/crashes-old/$t/"
    fi
    mkdir -p "$corpus" "$crashes"
    # Seeds are copied (never fuzzed in place: libFuzzer writes new inputs into its corpus directory).
    extra=""
    [ "$t" = convert ] && extra="tests/fixtures/bad/ply_*"
    [ "$t" = import ] && extra="tests/fixtures/import/head/head.mtl"
    [ "$t" = image ] && extra="tests/fixtures/import/*.jpg tests/fixtures/import/*.png tests/fixtures/bad/png_*"
    # shellcheck disable=SC2086
    for f in "$(seeds_of "$t")"/* tests/fixtures/bad/fuzz/"$t"/* $extra; do
        [ -f "$f" ] && cp "$f" "$corpus/"
    done
    # The hostile shapes of issue 23, small enough for -max_len: the guards must refuse them in-process.
    if [ "$t" = import ]; then
        . tests/support/hostile_models.sh
        deep_dae "$corpus/hostile_deep.dae" 300 && self_dae "$corpus/hostile_self.dae" &&
            deep_gltf "$corpus/hostile_deep.gltf" 300 && deep_glb "$corpus/hostile_deep.glb" 300 &&
            deep_fbx "$corpus/hostile_deep.fbx" 300 && bomb_fbx "$corpus/hostile_bomb.fbx" ||
            { say "import: cannot write the hostile seeds"; return 1; }
    fi
    # assimp's own leaks on malformed files are not ours to fix (tools/fuzz/import.lsan says which).
    lsan=${LSAN_OPTIONS:-}
    [ -f "tools/fuzz/$t.lsan" ] && lsan="suppressions=tools/fuzz/$t.lsan:print_suppressions=0"
    dict=""
    [ -f "tools/fuzz/$t.dict" ] && dict="-dict=tools/fuzz/$t.dict"
    log="$dir/fuzz_$t.run.log"
    # Regression: every input that once crashed must now pass (each file is run once).
    regress=$(ls tests/fixtures/bad/fuzz/"$t"/* 2>/dev/null)
    if [ -n "$regress" ]; then
        # shellcheck disable=SC2086
        if ! LSAN_OPTIONS="$lsan" "$dir/fuzz_$t" -artifact_prefix="$crashes/" $regress >"$dir/fuzz_$t.regress.log" 2>&1; then
            say "$t: a kept crash input fails again — see $dir/fuzz_$t.regress.log"
            return 1
        fi
    fi
    # shellcheck disable=SC2086
    LSAN_OPTIONS="$lsan" "$dir/fuzz_$t" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=512 \
        -max_len=65536 -print_final_stats=1 -artifact_prefix="$crashes/" $dict "$corpus" >"$log" 2>&1
    rc=$?
    stats=$(grep -E '^stat::number_of_executed_units' "$log" | awk '{print $2}')
    found=$(ls "$crashes" 2>/dev/null | head -n 1)
    if [ $rc -ne 0 ] || [ -n "$found" ]; then
        say "$t: FAILED (exit $rc) — $(grep -m1 -E 'ERROR|SUMMARY|deadly|timeout' "$log")"
        for c in "$crashes"/*; do [ -f "$c" ] && say "$t: reproducer $c  (rerun: $dir/fuzz_$t $c)"; done
        say "$t: full log $log; keep the input under tests/fixtures/bad/fuzz/$t/ once fixed"
        return 1
    fi
    say "$t: ok — ${stats:-?} inputs in ${seconds}s, corpus $(ls "$corpus" | wc -l) files, no crash"
    return 0
}

say "running each harness for ${seconds}s: $targets"
status=0
if [ "$jobs" -gt 1 ]; then
    pids=""
    for t in $targets; do run_one "$t" & pids="$pids $!"; done
    for p in $pids; do wait "$p" || status=1; done
else
    for t in $targets; do run_one "$t" || status=1; done
fi
if [ $status -eq 0 ]; then say "all harnesses clean"; else say "crashes found (see above)"; fi
exit $status
