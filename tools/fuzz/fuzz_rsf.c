// fuzz_rsf.c — libFuzzer entry point for the .rsf loader (src/splat/rsf_io.c). Built and run by `make fuzz`
// (tools/fuzz.sh); by hand:
//   clang -g -O1 -fsanitize=fuzzer,address,undefined -Isrc tools/fuzz/fuzz_rsf.c src/splat/splat.c \
//       src/splat/rsf_io.c src/core/core.c -lm -o /tmp/fuzz_rsf && /tmp/fuzz_rsf -dict=tools/fuzz/rsf.dict DIR
// Seed corpus: tests/fixtures/rsf/. Files that load also go through the converter's preview (the
// `--info --preview` path), so the header fields reach its projection with the CRC fixed up. Any input must load or fail cleanly (no crash, leak, hang or
// allocation beyond the input's size), failures must leave the output pointer alone and say why, and a
// file that loads must save back to the same bytes (docs/rsf.md: "save(load(f)) gives back f").
//
// Random bytes almost never get past the CRC, so inputs whose stored CRC is wrong are also tried with the
// CRC recomputed: the fuzzer then reaches the field checks behind it.
#include "pack/pack.h"
#include "splat/splat.h"

#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void load_one(const uint8_t *data, size_t size)
{
    rs_splat_cloud *c = (rs_splat_cloud *)(uintptr_t)1;  // a failed load must leave this untouched
    rs_error err = {0};
    if (rs_splat_load_memory(data, size, &c, &err) != RS_OK) {
        if (c != (rs_splat_cloud *)(uintptr_t)1 || err.msg[0] == 0) __builtin_trap();
        return;
    }
    // What loads must decode everywhere and write back byte for byte.
    rs_splat s;
    for (uint32_t i = 0; i < c->hdr.count; i += 1 + c->hdr.count / 64) rs_splat_get(c, i, &s);
    uint32_t n = rs_splat_lod_count(c, c->hdr.count / 2 + 1);
    if (n == 0 || n > c->hdr.count) __builtin_trap();
    void *back = NULL;
    size_t len = 0;
    if (rs_splat_save_memory(c, &back, &len, &err) != RS_OK) __builtin_trap();
    if (len != size || memcmp(back, data, size) != 0) __builtin_trap();
    // What `rouge-pack --info --preview` does with a valid header: the preview rasteriser projects every
    // splat by the header's frame (its float-to-int casts were once undefined for such files).
    rs_image img = {0};
    if (rs_pack_preview(c, 32, &img, &err) == RS_OK) rs_image_free(&img);
    free(back);
    rs_splat_destroy(c);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    load_one(data, size);
    if (size < 8) return 0;
    // The same bytes with a correct CRC over everything but the last four bytes.
    uint8_t *fixed = malloc(size);
    if (!fixed) return 0;
    memcpy(fixed, data, size);
    uint32_t crc = rs_crc32(0, fixed, size - 4);
    for (int k = 0; k < 4; k++) fixed[size - 4 + (size_t)k] = (uint8_t)(crc >> (8 * k));
    if (memcmp(fixed + size - 4, data + size - 4, 4) != 0) load_one(fixed, size);
    free(fixed);
    return 0;
}
