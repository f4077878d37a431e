// fuzz_look.c — libFuzzer entry point for the look-file parser and replay (src/formats/look.c). Build and run:
//   clang -g -O1 -fsanitize=fuzzer,address,undefined -Isrc tools/fuzz/fuzz_look.c src/formats/look.c src/makeup/makeup.c \
//       src/makeup/cosmetics.c src/core/core.c src/splat/splat.c src/splat/rsf_io.c -lm -o /tmp/fuzz_look && \
//       /tmp/fuzz_look tests/fixtures/looks
// Any input must parse or fail cleanly; a look that parses is replayed onto a small synthetic face
// (hostile stamps must be refused or painted, never crash), saved, and must parse again.
#include "formats/look.h"

#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static rs_splat_cloud *cloud;
static rs_makeup *layer;

// A 24 x 24 plane facing +z, face height 1 (built once: the fuzzer calls us millions of times).
static void setup(void)
{
    enum { K = 24 };
    static rs_splat s[K * K];
    for (int y = 0; y < K; y++)
        for (int x = 0; x < K; x++)
            s[y * K + x] = (rs_splat){{-0.5f + x / (K - 1.0f), -0.5f + y / (K - 1.0f), 0.0f}, {0, 0, 1}, 0.04f,
                                      {(uint8_t)(150 + 3 * x), (uint8_t)(120 + 2 * y), 110}, 1};
    rs_splat_header h;
    memset(&h, 0, sizeof h);
    h.mm_per_unit = 190.0f;
    h.face_height = 1.0f;
    h.forward[2] = 1.0f;
    h.up[1] = 1.0f;
    h.lod_count = 1;
    h.lods[0] = K * K;
    rs_error err = {0};
    if (rs_splat_create(s, K * K, &h, &cloud, &err) != RS_OK) __builtin_trap();
    if (rs_makeup_create(cloud, NULL, &layer, &err) != RS_OK) __builtin_trap();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (!layer) setup();
    rs_look *look = NULL;
    rs_error err = {0};
    if (rs_look_parse(data, size, &look, &err) != RS_OK) return 0;
    if (rs_look_apply(look, layer, NULL, &err) == RS_OK) {
        char *text = NULL;
        size_t len = 0;
        rs_look *back = NULL;
        if (rs_look_write_memory(layer, &text, &len, &err) != RS_OK) __builtin_trap();
        if (rs_look_parse(text, len, &back, &err) != RS_OK) __builtin_trap();
        rs_look_destroy(back);
        free(text);
    }
    rs_look_destroy(look);
    return 0;
}
