// fuzz_env.c — libFuzzer entry point for the .rse environment loader (src/formats/env.c). Built and run by
// `make fuzz` (tools/fuzz.sh); by hand:
//   clang -g -O1 -fsanitize=fuzzer,address,undefined -Isrc tools/fuzz/fuzz_env.c src/formats/env.c \
//       src/splat/rsf_io.c src/splat/splat.c src/core/core.c -lm -o /tmp/fuzz_env && /tmp/fuzz_env DIR
// Seed corpus: tests/fixtures/env/ (tiny.rse). Any input must load or fail cleanly (no crash, leak, hang or
// allocation beyond the input's size) with a message; a file that loads must save back to the same bytes
// (docs/env.md) and evaluate to finite SH irradiance. Inputs whose stored CRC is wrong are also tried with
// the CRC recomputed, so the fuzzer reaches the field checks behind it.
#include "formats/env.h"
#include "splat/splat.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void load_one(const uint8_t *data, size_t size)
{
    rs_env *e = NULL;
    rs_error err = {0};
    if (rs_env_load_memory(data, size, &e, &err) != RS_OK) {
        if (e != NULL || err.msg[0] == 0) __builtin_trap();
        return;
    }
    void *back = NULL;
    size_t len = 0;
    if (rs_env_save_memory(e, &back, &len, &err) != RS_OK) __builtin_trap();
    if (len != size || memcmp(back, data, size) != 0) __builtin_trap();
    free(back);
    float n[3] = {0.6f, 0.0f, 0.8f}, rgb[3], uv[2];
    float l = rs_env_sh_irradiance(e, n, rgb);
    if (!isfinite(l)) __builtin_trap();
    rs_env_dir_to_uv(e->light_dir, uv);
    for (int k = 0; k < e->level_count; k++) rs_rgb9e5_unpack(e->levels[k].rgb9e5[0], rgb);
    rs_env_destroy(e);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    load_one(data, size);
    if (size >= 8 && size <= (1u << 20)) {
        uint32_t crc = rs_crc32(0, data, size - 4), stored;
        memcpy(&stored, data + size - 4, 4);  // little-endian hosts (x86, ARM): the file's byte order
        if (crc != stored) {
            uint8_t *copy = malloc(size);
            if (!copy) return 0;
            memcpy(copy, data, size);
            for (int k = 0; k < 4; k++) copy[size - 4 + (size_t)k] = (uint8_t)(crc >> (8 * k));
            load_one(copy, size);
            free(copy);
        }
    }
    return 0;
}
