# rouge — GNU make build. `make run` and `make test` are all a newcomer needs (README.md).
#
# Layout of outputs (all under $(BUILD), git-ignored):
#   rouge, rouge-pack, rouge-imgdiff     programs
#   librouge.a, librouge.so.0            src/ (the library: no window-system or UI code; the .so exports
#                                        only the public API of include/rouge.h)
#   examples/                            examples/*.c built against the tree (tests/test_install.sh
#                                        builds them against the installed package)
#   libpack.a                            tools/pack/: the converter library (PLY reader, ...)
#   gen/shaders.c                        shaders_es/*.glsl embedded at build time
#   tests/test_*                         one test program per tests/test_*.c

BUILD    ?= build
PREFIX   ?= /usr/local
PKGS     := egl glesv2 glfw3 libpng cglm libzstd
CC       ?= cc
OPT      ?= -O2
# Messages are cut to their buffers on purpose, so GCC's format-truncation guesses are not errors.
CFLAGS   := -std=c11 $(OPT) -g -Wall -Wextra -Werror -Wno-format-truncation -MMD -MP $(EXTRA_CFLAGS)
LDFLAGS  := $(EXTRA_LDFLAGS)

PKG_CFLAGS := $(shell pkg-config --cflags $(PKGS) 2>/dev/null)
PKG_LIBS   := $(shell pkg-config --libs $(PKGS) 2>/dev/null)

LIB_SRC   := $(shell find src -name '*.c' | sort)
APP_SRC   := $(sort $(wildcard app/*.c))
TOOL_PROG := $(sort $(wildcard tools/rouge_*.c))
TOOL_LIB  := $(sort $(wildcard tools/pack/*.c))
TEST_SRC  := $(sort $(wildcard tests/test_*.c))
SHADERS   := $(sort $(wildcard shaders_es/*.glsl))

LIB_OBJ  := $(LIB_SRC:%.c=$(BUILD)/obj/%.o) $(BUILD)/obj/gen/shaders.o
APP_OBJ  := $(APP_SRC:%.c=$(BUILD)/obj/%.o)
APPLIB_OBJ := $(filter-out $(BUILD)/obj/app/main.o,$(APP_OBJ))
TLIB_OBJ := $(TOOL_LIB:%.c=$(BUILD)/obj/%.o)
TESTS    := $(TEST_SRC:tests/%.c=$(BUILD)/tests/%)
PROGS    := $(BUILD)/rouge $(TOOL_PROG:tools/rouge_%.c=$(BUILD)/rouge-%) $(BUILD)/rouge-env

# The library needs no window system: GLFW is the app's.
LIB_PKGS := egl glesv2 libpng cglm libzstd
LIB_LIBS := $(shell pkg-config --libs $(LIB_PKGS) 2>/dev/null) -lm -pthread
LIBS := $(BUILD)/librouge.a $(PKG_LIBS) -lm -pthread
# Tests also link the app's parts (UI, viewer, CLI) through libapp.a; the converter's tests libpack.
TEST_LIBS := $(BUILD)/libapp.a $(LIBS)
PACK_TESTS := test_pack test_ply test_import
# The converter's import (tools/pack/import_assimp.c, image_load.c): assimp, libjpeg-turbo, stb_image's header.
PACK_CFLAGS := $(shell pkg-config --cflags assimp stb 2>/dev/null)
PACK_LIBS   := $(shell pkg-config --libs assimp libjpeg 2>/dev/null)

VERSION  := 0.1.0
SOMAJOR  := 0
SONAME   := librouge.so.$(SOMAJOR)
EXAMPLES := $(patsubst examples/%.c,$(BUILD)/examples/%,$(sort $(wildcard examples/*.c)))

.PHONY: all deps run test test-full corpus bench asan fuzz figures envs clean install uninstall import-fixtures web \
        web-deps truth truth-deps
all: $(PROGS) $(TESTS) $(BUILD)/$(SONAME) $(EXAMPLES) $(BUILD)/rouge-truth-scene

# Installs what is missing (Debian packages), saying what and why; see tools/deps.sh.
deps:
	@sh tools/deps.sh

# Include paths say who may use what: the library sees only src/; the app adds app/, the tools tools/.
$(BUILD)/obj/src/%.o: src/%.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(PKG_CFLAGS) -fPIC -Iinclude -Isrc -DRS_DATADIR='"$(PREFIX)/share/rouge"' -c $< -o $@

$(BUILD)/obj/app/%.o: app/%.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(PKG_CFLAGS) -Iinclude -Isrc -Iapp -c $< -o $@

$(BUILD)/obj/tools/%.o: tools/%.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(PKG_CFLAGS) $(PACK_CFLAGS) -Iinclude -Isrc -Itools -c $< -o $@

$(BUILD)/obj/tests/%.o: tests/%.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(PKG_CFLAGS) -Iinclude -Isrc -Iapp -Itools -Itests -c $< -o $@

# Shaders are embedded at build time so an installed binary needs no shader directory.
$(BUILD)/embed_shaders: tools/embed_shaders.c
	@mkdir -p $(dir $@)
	$(CC) -std=c11 -O1 -Wall -Wextra -Werror $< -o $@

$(BUILD)/gen/shaders.c: $(BUILD)/embed_shaders $(SHADERS)
	@mkdir -p $(dir $@)
	$(BUILD)/embed_shaders shaders_es $@

$(BUILD)/obj/gen/shaders.o: $(BUILD)/gen/shaders.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(PKG_CFLAGS) -fPIC -Isrc -c $< -o $@

$(BUILD)/librouge.a: $(LIB_OBJ)
	@rm -f $@
	ar rcs $@ $^

$(BUILD)/libapp.a: $(APPLIB_OBJ)
	@rm -f $@
	ar rcs $@ $^

$(BUILD)/libpack.a: $(TLIB_OBJ)
	@mkdir -p $(dir $@)
	@rm -f $@
	ar rcs $@ $^

# The shared library exports rouge_* only (tools/librouge.map); everything rs_* stays inside.
$(BUILD)/$(SONAME): $(LIB_OBJ) tools/librouge.map
	$(CC) -shared -Wl,-soname,$(SONAME) -Wl,--version-script=tools/librouge.map $(LIB_OBJ) $(LIB_LIBS) $(LDFLAGS) -o $@

# Examples use nothing but rouge.h (+ EGL / GLFW / libpng for their own needs).
$(BUILD)/examples/%: examples/%.c include/rouge.h $(BUILD)/librouge.a
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(PKG_CFLAGS) -Iinclude $< $(BUILD)/librouge.a $(PKG_LIBS) -lm $(LDFLAGS) -o $@

$(BUILD)/rouge: $(APP_OBJ) $(BUILD)/librouge.a
	$(CC) $(CFLAGS) $(APP_OBJ) $(LIBS) $(LDFLAGS) -o $@

# Only the converter links the converter library.
$(BUILD)/rouge-pack: $(BUILD)/obj/tools/rouge_pack.o $(BUILD)/libpack.a $(BUILD)/librouge.a
	$(CC) $(CFLAGS) $< $(BUILD)/libpack.a $(PACK_LIBS) $(LIBS) $(LDFLAGS) -o $@

# rouge-env (tools-time only) reads OpenEXR through the C++ library (tools/env/exr_read.cpp: OpenEXR 3.1's
# C core cannot decode DWA, which blender-data's HDRIs use), so it links with the C++ compiler. env_bake.c
# (pure C: light, SH, prefiltering) is also linked into test_env_tool.
CXX ?= c++
ENV_BAKE_OBJ := $(BUILD)/obj/tools/env/env_bake.o
ENV_TOOL_OBJ := $(BUILD)/obj/tools/env/rouge_env.o $(ENV_BAKE_OBJ) $(BUILD)/obj/tools/env/env_read.o \
                $(BUILD)/obj/tools/env/exr_read.o
$(BUILD)/obj/tools/env/exr_read.o: tools/env/exr_read.cpp tools/env/exr_read.h
	@mkdir -p $(dir $@)
	$(CXX) -std=c++17 $(OPT) -g -Wall -Wextra -Werror $(EXTRA_CFLAGS) $(shell pkg-config --cflags OpenEXR) -c $< -o $@
$(BUILD)/rouge-env: $(ENV_TOOL_OBJ) $(BUILD)/librouge.a
	$(CXX) $(OPT) -g $(EXTRA_CFLAGS) $^ $(PKG_LIBS) $(shell pkg-config --libs OpenEXR) -lm $(LDFLAGS) -o $@

# rouge-truth-scene (tools/truth/: the path-traced reference's inputs) reads the same HDRIs as rouge-env.
TRUTH_SCENE_OBJ := $(BUILD)/obj/tools/truth/truth_scene.o $(ENV_BAKE_OBJ) $(BUILD)/obj/tools/env/env_read.o \
                   $(BUILD)/obj/tools/env/exr_read.o
$(BUILD)/rouge-truth-scene: $(TRUTH_SCENE_OBJ) $(BUILD)/librouge.a
	$(CXX) $(OPT) -g $(EXTRA_CFLAGS) $^ $(PKG_LIBS) $(shell pkg-config --libs OpenEXR) -lm -pthread $(LDFLAGS) -o $@

$(BUILD)/rouge-%: $(BUILD)/obj/tools/rouge_%.o $(BUILD)/librouge.a
	$(CC) $(CFLAGS) $< $(LIBS) $(LDFLAGS) -o $@

# ---- the web build (make web): the same library compiled to WebAssembly by Debian's emscripten ----
# build/web/ is a static site: index.html (the viewer page), rouge.js (the ES-module JS API), rouge_core.js +
# rouge_core.wasm (the library + web/rouge_web.c), the bundled face and environments. zlib, libpng and zstd
# are compiled from Debian's source packages (make web-deps fetches them; see tools/web_deps.sh). emcc's JS
# optimiser needs Debian's node modules (acorn) on NODE_PATH when node is not Debian's own.
EMCC      ?= emcc
WEB       := $(BUILD)/web
WEB_DEPS  := $(BUILD)/web-deps/src
WEB_OBJ   := $(BUILD)/web-obj
# clang (emcc) has no -Wno-format-truncation; the library's own warnings stay errors.
WEB_CFLAGS := -std=c11 -O3 -Wall -Wextra -Werror -Iinclude -Isrc -I$(WEB_OBJ)/include
WEB_3P_CFLAGS := -O3 -w -DNDEBUG -I$(WEB_OBJ)/include
WEB_ZLIB  := adler32 crc32 deflate inffast inflate inftrees trees zutil compress uncompr
WEB_PNG   := png pngerror pngget pngmem pngread pngrio pngrtran pngrutil pngset pngtrans pngwio pngwrite pngwtran pngwutil
WEB_3P_OBJ = $(WEB_ZLIB:%=$(WEB_OBJ)/zlib/%.o) $(WEB_PNG:%=$(WEB_OBJ)/png/%.o) \
             $(patsubst $(WEB_DEPS)/libzstd/lib/%.c,$(WEB_OBJ)/zstd/%.o,$(wildcard $(WEB_DEPS)/libzstd/lib/common/*.c \
               $(WEB_DEPS)/libzstd/lib/compress/*.c $(WEB_DEPS)/libzstd/lib/decompress/*.c))
WEB_LIB_OBJ := $(LIB_SRC:%.c=$(WEB_OBJ)/%.o) $(WEB_OBJ)/gen/shaders.o $(WEB_OBJ)/web/rouge_web.o
WEB_PAGE  := $(wildcard web/*.html web/*.js web/*.css)
PAREN     := (
WEB_EXPORTS := $(shell sed -n 's/^RW_API .*[ *]\(rw_[a-z_]*\)$(PAREN).*/_\1/p' web/rouge_web.c | tr '\n' ',')_malloc,_free,_rouge_free,_rouge_environment_count,_rouge_environment_name,_rouge_cosmetic_count,_rouge_result_name
WEB_LDFLAGS := -O3 -sMODULARIZE=1 -sEXPORT_ES6=1 -sEXPORT_NAME=createRougeCore -sENVIRONMENT=web \
    -sALLOW_MEMORY_GROWTH=1 -sINITIAL_MEMORY=64MB -sMAX_WEBGL_VERSION=2 -sMIN_WEBGL_VERSION=2 \
    -sEXPORTED_FUNCTIONS=$(WEB_EXPORTS) -sEXPORTED_RUNTIME_METHODS=FS,UTF8ToString,stringToUTF8,lengthBytesUTF8 \
    -sFILESYSTEM=1 -sMINIFY_HTML=0

web-deps:
	@sh tools/web_deps.sh $(BUILD)

web: web-deps
	@$(MAKE) --no-print-directory $(BUILD)/gen/shaders.c
	@$(MAKE) --no-print-directory $(WEB)/rouge_core.wasm $(WEB)/.assets $(BUILD)/web-bench/cpubench.js

$(WEB_OBJ)/include/.done:
	@mkdir -p $(dir $@)/cglm
	cp $(WEB_DEPS)/zlib/zlib.h $(WEB_DEPS)/zlib/zconf.h $(WEB_DEPS)/libpng1.6/png.h $(WEB_DEPS)/libpng1.6/pngconf.h \
	    $(WEB_DEPS)/libzstd/lib/zstd.h $(WEB_DEPS)/libzstd/lib/zstd_errors.h $(dir $@)
	cp $(WEB_DEPS)/libpng1.6/scripts/pnglibconf.h.prebuilt $(dir $@)/pnglibconf.h
	cp -r $$(pkg-config --variable=includedir cglm)/cglm/. $(dir $@)/cglm/
	@touch $@

$(WEB_OBJ)/zlib/%.o: $(WEB_DEPS)/zlib/%.c $(WEB_OBJ)/include/.done
	@mkdir -p $(dir $@)
	$(EMCC) $(WEB_3P_CFLAGS) -c $< -o $@
$(WEB_OBJ)/png/%.o: $(WEB_DEPS)/libpng1.6/%.c $(WEB_OBJ)/include/.done
	@mkdir -p $(dir $@)
	$(EMCC) $(WEB_3P_CFLAGS) -DPNG_ARM_NEON_OPT=0 -c $< -o $@
$(WEB_OBJ)/zstd/%.o: $(WEB_DEPS)/libzstd/lib/%.c $(WEB_OBJ)/include/.done
	@mkdir -p $(dir $@)
	$(EMCC) $(WEB_3P_CFLAGS) -DZSTD_MULTITHREAD=0 -DZSTD_DISABLE_ASM -c $< -o $@
$(WEB_OBJ)/src/%.o: src/%.c $(WEB_OBJ)/include/.done
	@mkdir -p $(dir $@)
	$(EMCC) $(WEB_CFLAGS) -MMD -MP -DRS_DATADIR='"/rouge"' -c $< -o $@
$(WEB_OBJ)/gen/shaders.o: $(BUILD)/gen/shaders.c $(WEB_OBJ)/include/.done
	@mkdir -p $(dir $@)
	$(EMCC) $(WEB_CFLAGS) -c $< -o $@
$(WEB_OBJ)/web/%.o: web/%.c include/rouge.h $(WEB_OBJ)/include/.done
	@mkdir -p $(dir $@)
	$(EMCC) $(WEB_CFLAGS) -c $< -o $@

$(WEB_OBJ)/librouge.a: $(filter-out $(WEB_OBJ)/web/%,$(WEB_LIB_OBJ)) $(WEB_3P_OBJ)
	@rm -f $@
	emar rcs $@ $^

EMCC_LINK := NODE_PATH=/usr/share/nodejs$${NODE_PATH:+:$$NODE_PATH} $(EMCC)
$(WEB)/rouge_core.wasm: $(WEB_OBJ)/web/rouge_web.o $(WEB_OBJ)/librouge.a
	@mkdir -p $(dir $@)
	$(EMCC_LINK) $(WEB_LDFLAGS) $^ -o $(WEB)/rouge_core.js

# The CPU-side work of a page (tools/rouge_cpubench.c) as WebAssembly under node, for make bench's ratio.
$(WEB_OBJ)/tools/%.o: tools/%.c $(WEB_OBJ)/include/.done
	@mkdir -p $(dir $@)
	$(EMCC) $(WEB_CFLAGS) -Itools -c $< -o $@
$(BUILD)/web-bench/cpubench.js: $(WEB_OBJ)/tools/rouge_cpubench.o $(WEB_OBJ)/librouge.a
	@mkdir -p $(dir $@)
	$(EMCC_LINK) -O3 -sENVIRONMENT=node -sNODERAWFS=1 -sSINGLE_FILE=1 -sALLOW_MEMORY_GROWTH=1 -sINITIAL_MEMORY=64MB $^ -o $@

# The page, the JS API, the bundled face and environments (with their licences).
$(WEB)/.assets: $(WEB_PAGE) examples/web/index.html assets/face.rsf $(wildcard assets/env/*.rse) assets/README.md \
                assets/env/README.md
	@mkdir -p $(WEB)/env
	cp $(WEB_PAGE) $(WEB)/
	cp examples/web/index.html $(WEB)/example.html
	cp assets/face.rsf assets/README.md $(WEB)/
	cp assets/env/*.rse assets/env/README.md $(WEB)/env/
	@touch $@

TEST_SUPPORT_OBJ := $(patsubst %.c,$(BUILD)/obj/%.o,$(sort $(wildcard tests/support/*.c)))

$(BUILD)/tests/%: $(BUILD)/obj/tests/%.o $(TEST_SUPPORT_OBJ) $(BUILD)/libapp.a $(BUILD)/librouge.a $(BUILD)/libpack.a \
                  $(ENV_BAKE_OBJ)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $< $(TEST_SUPPORT_OBJ) $(if $(filter $(PACK_TESTS),$*),$(BUILD)/libpack.a $(PACK_LIBS)) \
	    $(if $(filter test_env_tool,$*),$(ENV_BAKE_OBJ)) $(TEST_LIBS) $(LDFLAGS) -o $@

# test_env_specular integrates over the source captures (OpenEXR, read as rouge-env reads them): it links
# rouge-env's reader and bake with the C++ compiler.
ENV_READ_OBJ := $(ENV_BAKE_OBJ) $(BUILD)/obj/tools/env/env_read.o $(BUILD)/obj/tools/env/exr_read.o
$(BUILD)/tests/test_env_specular: $(BUILD)/obj/tests/test_env_specular.o $(TEST_SUPPORT_OBJ) $(BUILD)/libapp.a \
                                  $(BUILD)/librouge.a $(ENV_READ_OBJ)
	@mkdir -p $(dir $@)
	$(CXX) $(OPT) -g $(EXTRA_CFLAGS) $< $(TEST_SUPPORT_OBJ) $(ENV_READ_OBJ) $(TEST_LIBS) \
	    $(shell pkg-config --libs OpenEXR) $(LDFLAGS) -o $@

# Regenerates the committed import fixtures that need JPEG encoding (tests/fixtures/import/head/, *.jpg)
# from ../shared/data (tools/make_import_fixtures.c; the rest come from tests/fixtures/import/make_fixtures.py).
$(BUILD)/make-import-fixtures: tools/make_import_fixtures.c $(BUILD)/libpack.a $(BUILD)/librouge.a
	$(CC) $(CFLAGS) $(PKG_CFLAGS) $(PACK_CFLAGS) -Isrc -Itools $< $(BUILD)/libpack.a $(PACK_LIBS) $(LIBS) $(LDFLAGS) -o $@

import-fixtures: $(BUILD)/make-import-fixtures
	mkdir -p tests/fixtures/import/head
	$(BUILD)/make-import-fixtures ../shared/data/leeperrysmith tests/fixtures/import

run: deps
	@$(MAKE) --no-print-directory all
	@sh tools/run.sh $(BUILD)

# The browser tests (tests/test_web.sh) need the web build: make test builds it too.
test: deps web-deps
	@$(MAKE) --no-print-directory all
	@$(MAKE) --no-print-directory web
	@sh tests/run.sh $(BUILD)

# make test plus the slow extras it leaves out to stay within minutes: valgrind on the bundled 600k face
# (make test runs the same render under valgrind on a 3000-splat face).
test-full: deps web-deps
	@$(MAKE) --no-print-directory all
	@$(MAKE) --no-print-directory web
	@RS_VALGRIND_FACE=1 sh tests/run.sh $(BUILD)

# The test suite under AddressSanitizer + UndefinedBehaviorSanitizer, in its own build directory.
asan: deps
	@$(MAKE) --no-print-directory BUILD=build-asan OPT=-O1 \
	    EXTRA_CFLAGS='-fsanitize=address,undefined,float-cast-overflow -fno-omit-frame-pointer -fno-sanitize-recover=all' \
	    EXTRA_LDFLAGS='-fsanitize=address,undefined' all
	@ASAN_OPTIONS=detect_leaks=1:abort_on_error=0 LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan.supp:print_suppressions=0 \
	    UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 sh tests/run.sh build-asan

# The larger third-party corpus (tests/corpus.sh): ../shared/data and assimp's test models (Debian's
# assimp-testmodels, 20 MB, installed here only: make test's fixtures are in tests/fixtures/corpus).
corpus: deps
	@dpkg -s assimp-testmodels >/dev/null 2>&1 || { echo "corpus: installing assimp-testmodels (assimp's BSD test models)"; \
	    $$( [ "$$(id -u)" -eq 0 ] || echo sudo ) apt-get install -y assimp-testmodels; }
	@$(MAKE) --no-print-directory all
	@sh tests/corpus.sh $(BUILD)

bench: deps
	@$(MAKE) --no-print-directory all
	@sh tools/bench.sh $(BUILD)

figures: deps
	@$(MAKE) --no-print-directory all
	@sh tools/figures.sh $(BUILD)

fuzz: deps
	@sh tools/fuzz.sh

# make install [PREFIX=/usr/local] [DESTDIR=]: the header, both libraries, rouge.pc, the programs and
# the bundled face and environments they open by default (share/rouge). Nothing is rebuilt: the programs
# look next to their bin/, the library next to its own lib/ (found at run time), so a plain `make` installs
# to any PREFIX. `make uninstall` removes exactly these files by name (never by glob: another version's
# library or an .rse file you added stays), the library links only while they point at this version, and
# the folders install made once they are empty.
INSTALL_PROGS := $(BUILD)/rouge $(BUILD)/rouge-pack $(BUILD)/rouge-imgdiff $(BUILD)/rouge-profile
INSTALL_ENVS  := $(notdir $(sort $(wildcard assets/env/*.rse))) README.md
LIB_REAL      := $(SONAME).$(VERSION:$(SOMAJOR).%=%)
# cglm is header-only and only src/ includes it: a host linking rouge needs no cglm.pc.
PC_REQUIRES   := $(filter-out cglm,$(LIB_PKGS))
I := $(DESTDIR)$(PREFIX)
install: $(INSTALL_PROGS) $(BUILD)/librouge.a $(BUILD)/$(SONAME)
	install -d $(I)/bin $(I)/include $(I)/lib/pkgconfig $(I)/share/rouge/env
	install -m 755 $(INSTALL_PROGS) $(I)/bin/
	install -m 644 include/rouge.h $(I)/include/
	install -m 644 $(BUILD)/librouge.a $(I)/lib/
	install -m 755 $(BUILD)/$(SONAME) $(I)/lib/$(LIB_REAL)
	ln -sf $(LIB_REAL) $(I)/lib/$(SONAME)
	ln -sf $(SONAME) $(I)/lib/librouge.so
	printf '%s\n' 'prefix=$(PREFIX)' 'exec_prefix=$${prefix}' 'libdir=$${prefix}/lib' 'includedir=$${prefix}/include' '' \
	    'Name: rouge' 'Description: realistic skin rendering and makeup painting on face scans (OpenGL ES 3)' \
	    'Version: $(VERSION)' 'Requires.private: $(PC_REQUIRES)' 'Libs: -L$${libdir} -lrouge' \
	    'Libs.private: -lm -pthread' 'Cflags: -I$${includedir}' > $(I)/lib/pkgconfig/rouge.pc
	install -m 644 assets/face.rsf assets/README.md $(I)/share/rouge/
	install -m 644 $(addprefix assets/env/,$(INSTALL_ENVS)) $(I)/share/rouge/env/

uninstall:
	rm -f $(addprefix $(I)/bin/,$(notdir $(INSTALL_PROGS))) $(I)/include/rouge.h $(I)/lib/librouge.a
	for l in librouge.so $(SONAME); do \
	    [ -L $(I)/lib/$$l ] && [ "$$(readlink -f $(I)/lib/$$l)" = "$$(readlink -f $(I)/lib/$(LIB_REAL))" ] && \
	        rm -f $(I)/lib/$$l; true; \
	done
	rm -f $(I)/lib/$(LIB_REAL) $(I)/lib/pkgconfig/rouge.pc
	rm -f $(I)/share/rouge/face.rsf $(I)/share/rouge/README.md $(addprefix $(I)/share/rouge/env/,$(INSTALL_ENVS))
	-rmdir $(I)/share/rouge/env $(I)/share/rouge $(I)/lib/pkgconfig 2>/dev/null

# The bundled lighting environments from blender-data's CC0 HDRIs (assets/env/README.md).
ENV_SRC := /usr/share/blender/datafiles/studiolights/world
ENV_NOTE = Source: Blender studiolights world/$(2).exr (Debian blender-data), by Greg Zaal (HDRI Haven), CC0 1.0
envs: deps $(BUILD)/rouge-env
	$(BUILD)/rouge-env $(ENV_SRC)/studio.exr -o assets/env/studio.rse --name studio --notes "$(call ENV_NOTE,,studio)"
	$(BUILD)/rouge-env $(ENV_SRC)/city.exr -o assets/env/daylight.rse --name daylight --notes "$(call ENV_NOTE,,city)"
	$(BUILD)/rouge-env $(ENV_SRC)/interior.exr -o assets/env/office.rse --name office --notes "$(call ENV_NOTE,,interior)"
	$(BUILD)/rouge-env $(ENV_SRC)/sunset.exr -o assets/env/sunset.rse --name sunset --notes "$(call ENV_NOTE,,sunset)"

# The path-traced reference (tests/fixtures/truth/README.md): Debian's Blender renders the scan face.rsf was made from
# (../shared/data/leeperrysmith) under every bundled environment; tests/test_truth.c compares rouge to it.
# Slow (minutes of CPU a view); not part of make test. truth-deps installs Blender (and numpy for its Python).
truth-deps: deps
	@sh tools/deps.sh truth

truth: truth-deps $(BUILD)/rouge-truth-scene
	@sh tools/truth/truth.sh $(BUILD)

clean:
	rm -rf build build-*

.SECONDARY:
-include $(shell find $(BUILD)/obj $(BUILD)/web-obj -name '*.d' 2>/dev/null)
