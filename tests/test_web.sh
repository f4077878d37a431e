#!/bin/sh
# The web build in a real browser (tests/web/run.mjs): Debian's chromium, WebGL 2 on SwiftShader, touch
# and pen events over the DevTools protocol. `make test` builds build/web and installs what this needs
# (make web-deps).
build=${1:-build}
# Another build folder (make asan's build-asan) builds no wasm: the page is the same for every native build.
if [ "$build" != build ] && [ ! -d "$build/web" ]; then
    echo "skip - web: $build has no web build (the browser tests run on build/: make test)"
    exit 0
fi
if [ ! -f "$build/web/rouge_core.wasm" ] || [ ! -f "$build/web/index.html" ]; then
    echo "FAIL - web: $build/web is not built (make web)"
    exit 1
fi
if [ ! -d tests/web/node_modules/puppeteer-core ]; then
    echo "FAIL - web: puppeteer-core is not installed (make web-deps)"
    exit 1
fi
exec node tests/web/run.mjs "$build"
