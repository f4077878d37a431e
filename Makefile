# rouge — GNU make build. `make run` and `make test` are all a newcomer needs (README.md).
#
# Layout of outputs (all under $(BUILD), git-ignored):
#   rouge, rouge-pack, rouge-imgdiff     programs
#   librouge.a                           src/ (the library: no window-system or UI code)
#   libpack.a                            tools/pack/: the converter library (PLY reader, ...)
#   gen/shaders.c                        shaders_es/*.glsl embedded at build time
#   tests/test_*                         one test program per tests/test_*.c

BUILD    ?= build
PKGS     := egl glesv2 glfw3 libpng cglm
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
PROGS    := $(BUILD)/rouge $(TOOL_PROG:tools/rouge_%.c=$(BUILD)/rouge-%)

LIBS := $(BUILD)/libpack.a $(BUILD)/librouge.a $(PKG_LIBS) -lm
# Tests also link the app's parts (UI, viewer, CLI) through libapp.a.
TEST_LIBS := $(BUILD)/libapp.a $(LIBS)

.PHONY: all deps run test bench asan fuzz figures clean
all: $(PROGS) $(TESTS)

# Installs what is missing (Debian packages), saying what and why; see tools/deps.sh.
deps:
	@sh tools/deps.sh

# Include paths say who may use what: the library sees only src/; the app adds app/, the tools tools/.
$(BUILD)/obj/src/%.o: src/%.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(PKG_CFLAGS) -fPIC -Iinclude -Isrc -c $< -o $@

$(BUILD)/obj/app/%.o: app/%.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(PKG_CFLAGS) -Iinclude -Isrc -Iapp -c $< -o $@

$(BUILD)/obj/tools/%.o: tools/%.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(PKG_CFLAGS) -Iinclude -Isrc -Itools -c $< -o $@

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

$(BUILD)/rouge: $(APP_OBJ) $(BUILD)/librouge.a $(BUILD)/libpack.a
	$(CC) $(CFLAGS) $(APP_OBJ) $(LIBS) $(LDFLAGS) -o $@

$(BUILD)/rouge-%: $(BUILD)/obj/tools/rouge_%.o $(BUILD)/librouge.a $(BUILD)/libpack.a
	$(CC) $(CFLAGS) $< $(LIBS) $(LDFLAGS) -o $@

TEST_SUPPORT_OBJ := $(patsubst %.c,$(BUILD)/obj/%.o,$(sort $(wildcard tests/support/*.c)))

$(BUILD)/tests/%: $(BUILD)/obj/tests/%.o $(TEST_SUPPORT_OBJ) $(BUILD)/libapp.a $(BUILD)/librouge.a $(BUILD)/libpack.a
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $< $(TEST_SUPPORT_OBJ) $(TEST_LIBS) $(LDFLAGS) -o $@

run: deps
	@$(MAKE) --no-print-directory all
	@sh tools/run.sh $(BUILD)

test: deps
	@$(MAKE) --no-print-directory all
	@sh tests/run.sh $(BUILD)

# The test suite under AddressSanitizer + UndefinedBehaviorSanitizer, in its own build directory.
asan: deps
	@$(MAKE) --no-print-directory BUILD=build-asan OPT=-O1 \
	    EXTRA_CFLAGS='-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all' \
	    EXTRA_LDFLAGS='-fsanitize=address,undefined' all
	@ASAN_OPTIONS=detect_leaks=1:abort_on_error=0 LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan.supp:print_suppressions=0 \
	    UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 sh tests/run.sh build-asan

bench: deps
	@$(MAKE) --no-print-directory all
	@sh tools/bench.sh $(BUILD)

figures: deps
	@$(MAKE) --no-print-directory all
	@sh tools/figures.sh $(BUILD)

fuzz: deps
	@sh tools/fuzz.sh

clean:
	rm -rf build build-*

.SECONDARY:
-include $(shell find $(BUILD)/obj -name '*.d' 2>/dev/null)
