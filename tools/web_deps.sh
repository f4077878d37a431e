#!/bin/sh
# make web-deps: what the web build and the browser tests need, from Debian's packages and sources and the
# npm registry (pinned by tests/web/package-lock.json), installing only what is missing.
#   - emscripten (Debian's 3.1.x; its cache is prebuilt and frozen, so no Emscripten ports): the compiler;
#   - the C libraries the wasm links, built from Debian's own source packages with emcc (Makefile): zlib,
#     libpng1.6, libzstd — fetched with `apt-get source --download-only` through a private deb-src list made
#     from this machine's own apt sources, unpacked into BUILD/web-deps/src;
#   - chromium (headless, SwiftShader's WebGL 2) and node + puppeteer-core for tests/web.
# Usage: tools/web_deps.sh BUILD_DIR [--no-browser]
set -u
build=${1:-build}
browser=1
[ "${2:-}" = --no-browser ] && browser=0
deps=$(mkdir -p "$build/web-deps" && cd "$build/web-deps" && pwd) || exit 1
die() { echo "rouge web: $*" >&2; exit 1; }

sudo=""
[ "$(id -u)" != 0 ] && command -v sudo >/dev/null 2>&1 && sudo=sudo
apt_install() {
    command -v apt-get >/dev/null 2>&1 || die "missing: $* — install these Debian packages"
    echo "rouge web: installing Debian packages: $*"
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "$@" >/dev/null 2>&1 ||
        { $sudo apt-get update -qq >/dev/null 2>&1 &&
          DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "$@" >/dev/null; } ||
        die "apt-get install $* failed"
}

missing=""
command -v emcc >/dev/null 2>&1 || missing="$missing emscripten"
if [ $browser = 1 ]; then
    command -v chromium >/dev/null 2>&1 || missing="$missing chromium"
    command -v node >/dev/null 2>&1 || missing="$missing nodejs"
    command -v npm >/dev/null 2>&1 || missing="$missing npm"
fi
command -v dpkg-source >/dev/null 2>&1 || missing="$missing dpkg-dev"
[ -n "$missing" ] && apt_install $missing

# Versions, named in errors: emcc 3.1 (Debian 12's 3.1.6 is what this is built and tested with), node 18+.
emv=$(emcc --version 2>/dev/null | sed -n '1s/.*) \([0-9][0-9.]*\).*/\1/p')
case "$emv" in
    3.1.*|3.[2-9]*|[4-9].*) ;;
    *) die "emcc ${emv:-(no version)} found; rouge's web build needs Emscripten 3.1 or newer (Debian 12: emscripten 3.1.6)" ;;
esac
if [ $browser = 1 ]; then
    nv=$(node --version 2>/dev/null | sed 's/^v//')
    [ "${nv%%.*}" -ge 18 ] 2>/dev/null || die "node ${nv:-(none)} found; the browser tests need Node.js 18 or newer"
    cv=$(chromium --version 2>/dev/null | sed -n 's/^Chromium \([0-9]*\).*/\1/p')
    [ "${cv:-0}" -ge 100 ] 2>/dev/null || die "chromium ${cv:-(none)} found; the browser tests need Chromium 100 or newer (WebGL 2)"
fi

# Debian's sources of the libraries the wasm links (the native build uses the installed -dev packages).
if [ ! -f "$deps/src/.done" ]; then
    mkdir -p "$deps/apt/lists/partial" "$deps/dl" "$deps/src"
    list="$deps/apt/sources.list"
    : > "$list"
    # deb-src twins of this machine's deb lines (one-line and deb822 formats); security updates are left out:
    # they publish only patches over the same upstream tarballs.
    for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list; do
        [ -f "$f" ] && sed -n 's/^deb \(.*debian[^ ]* .*\)$/deb-src \1/p' "$f" | grep -v -- '-security' >> "$list"
    done
    for f in /etc/apt/sources.list.d/*.sources; do
        [ -f "$f" ] || continue
        awk 'BEGIN{RS="";ORS="\n\n"} /Types:[^\n]*deb/ && /Suites:/ && !/security/ && /debian/ {sub(/Types:[^\n]*/,"Types: deb-src"); print}' "$f" >> "$list.sources"
    done
    [ -f "$list.sources" ] && mv "$list.sources" "$deps/apt/debian.sources"
    o="-o Dir::Etc::SourceList=$list -o Dir::Etc::SourceParts=$deps/apt -o Dir::State::Lists=$deps/apt/lists -o Debug::NoLocking=1"
    # shellcheck disable=SC2086
    apt-get $o update -qq >/dev/null 2>&1 || die "apt-get update of Debian's source lists failed"
    (cd "$deps/dl" && apt-get $o source --download-only -qq zlib libpng1.6 libzstd >/dev/null 2>&1) ||
        die "apt-get source zlib libpng1.6 libzstd failed (Debian's source packages are needed for the wasm)"
    for pkg in zlib libpng1.6 libzstd; do
        dsc=$(ls "$deps/dl/${pkg}"_*.dsc 2>/dev/null | head -n 1)
        [ -n "$dsc" ] || die "no source package of $pkg was downloaded"
        rm -rf "$deps/src/$pkg"
        dpkg-source --no-check -x "$dsc" "$deps/src/$pkg" >/dev/null 2>&1 || die "dpkg-source -x $dsc failed"
    done
    touch "$deps/src/.done"
fi

# puppeteer-core (no browser download: it drives Debian's chromium), pinned by the committed lock file.
if [ $browser = 1 ] && [ ! -d tests/web/node_modules/puppeteer-core ]; then
    (cd tests/web && npm ci --no-audit --no-fund --ignore-scripts --loglevel=error >/dev/null) ||
        die "npm ci in tests/web failed (puppeteer-core from the npm registry)"
fi
exit 0
