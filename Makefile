# rouge — GNU make build. `make run` and `make test` are all a newcomer needs (README.md).
#
# Layout of outputs (all under $(BUILD), git-ignored):
#   rouge, rouge-pack, rouge-imgdiff     programs
#   librouge.a                           src/ (everything but src/app)
#   libpack.a                            tools/ library parts of the converter (PLY reader, ...)
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

LIB_SRC   := $(shell find src -name '*.c' -not -path 'src/app/*' | sort)
APP_SRC   := $(sort $(wildcard src/app/*.c))
TOOL_PROG := $(sort $(wildcard tools/rouge_*.c))
TOOL_LIB  := $(filter-out $(TOOL_PROG) tools/embed_shaders.c,$(sort $(wildcard tools/*.c)))
TEST_SRC  := $(sort $(wildcard tests/test_*.c))
SHADERS   := $(sort $(wildcard shaders_es/*.glsl))

LIB_OBJ  := $(LIB_SRC:%.c=$(BUILD)/obj/%.o) $(BUILD)/obj/gen/shaders.o
APP_OBJ  := $(APP_SRC:%.c=$(BUILD)/obj/%.o)
TLIB_OBJ := $(TOOL_LIB:%.c=$(BUILD)/obj/%.o)
TESTS    := $(TEST_SRC:tests/%.c=$(BUILD)/tests/%)
PROGS    := $(BUILD)/rouge $(TOOL_PROG:tools/rouge_%.c=$(BUILD)/rouge-%)

LIBS := $(BUILD)/libpack.a $(BUILD)/librouge.a $(PKG_LIBS) -lm

.PHONY: all deps run test bench asan fuzz figures clean
all: $(PROGS) $(TESTS)

# Installs what is missing (Debian packages), saying what and why; see tools/deps.sh.
deps:
	@sh tools/deps.sh

$(BUILD)/obj/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(PKG_CFLAGS) -Isrc -c $< -o $@

# Shaders are embedded at build time so an installed binary needs no shader directory.
$(BUILD)/embed_shaders: tools/embed_shaders.c
	@mkdir -p $(dir $@)
	$(CC) -std=c11 -O1 -Wall -Wextra -Werror $< -o $@

$(BUILD)/gen/shaders.c: $(BUILD)/embed_shaders $(SHADERS)
	@mkdir -p $(dir $@)
	$(BUILD)/embed_shaders shaders_es $@

$(BUILD)/obj/gen/shaders.o: $(BUILD)/gen/shaders.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(PKG_CFLAGS) -Isrc -c $< -o $@

$(BUILD)/librouge.a: $(LIB_OBJ)
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

$(BUILD)/tests/%: $(BUILD)/obj/tests/%.o $(BUILD)/obj/tests/harness.o $(BUILD)/librouge.a $(BUILD)/libpack.a
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $< $(BUILD)/obj/tests/harness.o $(LIBS) $(LDFLAGS) -o $@

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
