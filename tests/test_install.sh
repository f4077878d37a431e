#!/bin/sh
# `make install` into a scratch root (DESTDIR, PREFIX=/usr) gives a usable package: the files are there,
# librouge.so has a SONAME, exports only rouge_* and needs no GLFW, rouge.h compiles on its own, every
# examples/*.c builds with `pkg-config --cflags --libs rouge` against the installed tree (not the source
# tree) and links the installed librouge.so; the installed embed_headless paints one stroke on the
# installed face, and its PNG equals `rouge render` of the same view except where the stroke is; the
# installed rouge finds its default face; the installed library finds its environments from any working
# directory (beside its own lib/, though built for /usr/local); `pkg-config --libs rouge` needs no cglm.pc;
# uninstall removes exactly what install added (another version's library and a user's .rse stay, the
# lib/pkgconfig it made goes). About 10 s.
build=${1:-build}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
case "$build" in
*asan*) echo "skip - install_package: sanitizer build (the installed library would need the sanitizer runtime)"; exit 0 ;;
esac
root="$tmp/root"
ok() { echo "ok - $1"; }
fail() { echo "FAIL - $1: $2"; }

if ! make --no-print-directory -s BUILD="$build" install DESTDIR="$root" PREFIX=/usr >"$tmp/log" 2>&1; then
    fail install_runs "$(tail -n 3 "$tmp/log")"
    exit 1
fi
missing=""
for f in bin/rouge bin/rouge-pack bin/rouge-imgdiff include/rouge.h lib/librouge.a lib/librouge.so lib/librouge.so.0 \
         lib/pkgconfig/rouge.pc share/rouge/face.rsf share/rouge/README.md; do
    [ -e "$root/usr/$f" ] || missing="$missing $f"
done
if [ -z "$missing" ]; then ok install_files; else fail install_files "missing:$missing"; fi

so="$root/usr/lib/librouge.so.0"
if readelf -d "$so" 2>/dev/null | grep -q 'SONAME.*\[librouge\.so\.0\]'; then ok install_soname; else fail install_soname "no SONAME librouge.so.0"; fi
if nm -D --defined-only "$so" | awk '$2 == "T" && $3 !~ /^rouge_/' | grep -q .; then
    fail install_exports_public_only "$(nm -D --defined-only "$so" | awk '$2 == "T" && $3 !~ /^rouge_/' | head -3 | tr '\n' ' ')"
else
    ok install_exports_public_only
fi
if nm -D --undefined-only "$so" | grep -qi glfw || nm "$root/usr/lib/librouge.a" 2>/dev/null | grep -qi 'glfw'; then
    fail install_library_has_no_glfw "GLFW symbols in librouge"
else
    ok install_library_has_no_glfw
fi

# The header on its own: nothing but its own include directory, strict C11 and C++.
printf '#include <rouge.h>\nint main(void) { rouge_view v = {0}; (void)v; return (int)ROUGE_OK; }\n' >"$tmp/alone.c"
if cc -std=c11 -Wall -Wextra -Werror -pedantic -I"$root/usr/include" -c "$tmp/alone.c" -o "$tmp/alone.o" 2>"$tmp/err"; then
    ok install_header_compiles_alone
else
    fail install_header_compiles_alone "$(head -n 2 "$tmp/err")"
fi
if command -v c++ >/dev/null 2>&1; then
    if c++ -Wall -Werror -I"$root/usr/include" -x c++ -c "$tmp/alone.c" -o "$tmp/alone_cc.o" 2>"$tmp/err"; then
        ok install_header_compiles_as_cxx
    else
        fail install_header_compiles_as_cxx "$(head -n 2 "$tmp/err")"
    fi
fi

# Every example against the installed package only.
export PKG_CONFIG_PATH="$root/usr/lib/pkgconfig" PKG_CONFIG_SYSROOT_DIR="$root"
for src in examples/*.c; do
    name=$(basename "$src" .c)
    extra="egl libpng"
    grep -q 'GLFW/glfw3.h' "$src" && extra="glfw3"
    # shellcheck disable=SC2046
    if cc -std=c11 -Wall -Wextra -Werror "$src" $(pkg-config --cflags --libs rouge $extra) -o "$tmp/$name" 2>"$tmp/err"; then
        if readelf -d "$tmp/$name" | grep -q 'NEEDED.*librouge\.so\.0'; then ok "install_example_builds_$name"
        else fail "install_example_builds_$name" "does not link the installed librouge.so"; fi
    else
        fail "install_example_builds_$name" "$(head -n 3 "$tmp/err")"
    fi
done
unset PKG_CONFIG_PATH PKG_CONFIG_SYSROOT_DIR

# cglm is header-only and private to src/: a host without cglm.pc still gets rouge's flags.
pcdir="$tmp/pc"
mkdir -p "$pcdir"
for d in $(pkg-config --variable pc_path pkg-config | tr ':' ' '); do
    for f in "$d"/*.pc; do
        [ -e "$f" ] && [ "$(basename "$f")" != cglm.pc ] && ln -sf "$f" "$pcdir/" 2>/dev/null
    done
done
if PKG_CONFIG_LIBDIR="$pcdir:$root/usr/lib/pkgconfig" PKG_CONFIG_SYSROOT_DIR="$root" \
    pkg-config --cflags --libs rouge >"$tmp/pc.out" 2>&1 && grep -q -- '-lrouge' "$tmp/pc.out"; then
    ok install_pkg_config_needs_no_cglm
else
    fail install_pkg_config_needs_no_cglm "$(head -n 2 "$tmp/pc.out")"
fi

# embed_headless: a PNG of the face with one lipstick stroke; the same view through `rouge render` (the
# mobile pipeline, the defaults) is the reference: identical but for the stroke.
# Run from a folder without assets/: the installed library (built for /usr/local, installed to /usr under
# a DESTDIR) must find its environments beside itself, not in the working directory.
mkdir -p "$tmp/elsewhere"
if [ -x "$tmp/embed_headless" ]; then
    if (cd "$tmp/elsewhere" && LD_LIBRARY_PATH="$root/usr/lib" "$tmp/embed_headless" "$root/usr/share/rouge/face.rsf" \
        "$tmp/eh.png") 2>"$tmp/err"; then
        "$build/rouge" render "$root/usr/share/rouge/face.rsf" -o "$tmp/ref.png" --size 256x256 --pipeline mobile >/dev/null 2>&1
        "$build/rouge-imgdiff" "$tmp/ref.png" "$tmp/eh.png" --threshold 8 >"$tmp/m8" 2>&1
        "$build/rouge-imgdiff" "$tmp/ref.png" "$tmp/eh.png" --threshold 0 >"$tmp/m0" 2>&1
        f8=$(awk '$1 == "frac_over" {print $2}' "$tmp/m8")
        f0=$(awk '$1 == "frac_over" {print $2}' "$tmp/m0")
        psnr=$(awk '$1 == "psnr_db" {print $2}' "$tmp/m8")
        # A stroke across the lips: ~0.1-1 % of the picture visibly changed, nothing else touched.
        if awk -v a="$f8" -v b="$f0" -v p="$psnr" 'BEGIN { exit !(a > 0.0008 && a < 0.02 && b < 0.03 && p > 38) }'; then
            ok install_embed_headless_paints_one_stroke
        else
            fail install_embed_headless_paints_one_stroke "vs rouge render: frac_over(8) $f8, frac_over(0) $f0, psnr $psnr"
            cp "$tmp/eh.png" "${RS_TEST_OUT:-$build/test-out}/embed_headless.actual.png" 2>/dev/null
        fi
    else
        fail install_embed_headless_paints_one_stroke "$(head -n 1 "$tmp/err")"
    fi
fi

# The installed program opens its installed face when none is named (from a directory without assets/).
if (cd "$tmp/elsewhere" && "$root/usr/bin/rouge" render -o x.png --size 32x32 --max-splats 2000 >/dev/null 2>"$tmp/err") &&
    [ -s "$tmp/elsewhere/x.png" ]; then
    ok install_rouge_finds_its_face
else
    fail install_rouge_finds_its_face "$(head -n 1 "$tmp/err")"
fi

# What is not install's stays: another version's library and an environment the user added.
echo other >"$root/usr/lib/librouge.so.0.9.0"
echo mine >"$root/usr/share/rouge/env/mine.rse"
if make --no-print-directory -s BUILD="$build" uninstall DESTDIR="$root" PREFIX=/usr >"$tmp/log" 2>&1 &&
    [ "$(cd "$root" && find . -type f -o -type l | sort | tr '\n' ' ')" = "./usr/lib/librouge.so.0.9.0 ./usr/share/rouge/env/mine.rse " ] &&
    [ ! -d "$root/usr/lib/pkgconfig" ]; then
    ok install_uninstall_removes_exactly_what_it_added
else
    fail install_uninstall_removes_exactly_what_it_added "left: $(cd "$root" && find . -type f -o -type l | head -4 | tr '\n' ' ')$([ -d "$root/usr/lib/pkgconfig" ] && echo 'and lib/pkgconfig')"
fi
