// fuzz_rsf.c — libFuzzer entry point for the .rsf loaders (src/splat/rsf_io.c: version 1 and the dispatch;
// src/splat/rsf_v2.c: version 2's chunks, zstd planes and the progressive loader). Built and run by
// `make fuzz` (tools/fuzz.sh); by hand:
//   clang -g -O1 -fsanitize=fuzzer,address,undefined -Isrc -Itools tools/fuzz/fuzz_rsf.c build/fuzz/lib/libpack.a \
//       build/fuzz/lib/librouge.a -lzstd -lpng -lm -o /tmp/fuzz_rsf && /tmp/fuzz_rsf -dict=tools/fuzz/rsf.dict DIR
// Seed corpus: tests/fixtures/rsf/ (tiny_v1, tiny_v2: stored chunks, small_v2: zstd-coded chunks). Files
// that load also go through the converter's preview (the `--info --preview` path), so the header fields
// reach its projection. Any input must load or fail cleanly (no crash, leak, hang or allocation beyond
// what the input can justify), failures must leave the output pointer alone and say why; a version-1 file
// that loads must save back to the same bytes (docs/rsf.md), a version-2 file to the same records.
// The progressive loader, fed the same bytes in pieces of a size taken from the input, must agree with
// the whole-file loader: the same success and the same cloud, and previews of whatever level is ready.
//
// Random bytes almost never get past a CRC, so inputs are also tried with their CRCs recomputed: the
// trailing one of version 1, or version 2's header CRC and each chunk's CRC in the table.
#include "pack/pack.h"
#include "splat/splat.h"

#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static uint32_t rd(const uint8_t *p) { return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24; }
static void wr(uint8_t *p, uint32_t v)
{
    for (int k = 0; k < 4; k++) p[k] = (uint8_t)(v >> (8 * k));
}

// The same bytes fed to a stream loader (size unknown) in pieces of `piece` bytes; returns the cloud or NULL.
static rs_splat_cloud *load_stream(const uint8_t *data, size_t size, size_t piece)
{
    rs_splat_loader *l = NULL;
    rs_error err = {0};
    if (rs_splat_loader_create(NULL, &l, &err) != RS_OK) __builtin_trap();
    rs_splat_cloud *c = NULL;
    bool ok = true;
    uint32_t shown = 0;
    for (size_t at = 0; ok && at < size; at += piece) {
        ok = rs_splat_loader_feed(l, data + at, size - at < piece ? size - at : piece, &err) == RS_OK;
        uint32_t ready = rs_splat_loader_ready(l);
        if (ok && ready > shown) {
            rs_splat_cloud *p = NULL;
            if (rs_splat_loader_preview(l, ready, &p, &err) == RS_OK) {
                if (p->hdr.count != ready) __builtin_trap();
                rs_splat_destroy(p);
            }
            shown = ready;
        }
    }
    if (ok && rs_splat_loader_finish(l, &c, &err) != RS_OK) c = NULL;
    if (!c && err.msg[0] == 0) __builtin_trap();
    rs_splat_loader_destroy(l);
    return c;
}

static void load_one(const uint8_t *data, size_t size)
{
    rs_splat_cloud *c = (rs_splat_cloud *)(uintptr_t)1;  // a failed load must leave this untouched
    rs_error err = {0};
    size_t piece = 1 + (size ? data[size / 2] : 0) * 7;
    rs_splat_cloud *s = load_stream(data, size, piece);
    if (rs_splat_load_memory(data, size, &c, &err) != RS_OK) {
        if (c != (rs_splat_cloud *)(uintptr_t)1 || err.msg[0] == 0) __builtin_trap();
        if (s) __builtin_trap();  // the stream accepted what the whole-file loader refused
        return;
    }
    if (!s || s->hdr.count != c->hdr.count || memcmp(s->packed, c->packed, c->hdr.count * sizeof *c->packed) != 0)
        __builtin_trap();
    rs_splat_destroy(s);
    // What loads must decode everywhere and write back: a v1 file byte for byte, any file record for record.
    rs_splat sp;
    for (uint32_t i = 0; i < c->hdr.count; i += 1 + c->hdr.count / 64) rs_splat_get(c, i, &sp);
    uint32_t n = rs_splat_lod_count(c, c->hdr.count / 2 + 1);
    if (n == 0 || n > c->hdr.count) __builtin_trap();
    uint32_t version = rd(data + 4);
    void *back = NULL;
    size_t len = 0;
    if (rs_splat_save_memory_with(c, &(rs_splat_save_desc){.version = version, .level = 1}, &back, &len, &err) != RS_OK)
        __builtin_trap();
    if (version == 1 && (len != size || memcmp(back, data, size) != 0)) __builtin_trap();
    rs_splat_cloud *d = NULL;
    if (rs_splat_load_memory(back, len, &d, &err) != RS_OK ||
        memcmp(d->packed, c->packed, c->hdr.count * sizeof *c->packed) != 0)
        __builtin_trap();
    rs_splat_destroy(d);
    // What `rouge-pack --info --preview` does with a valid header: the preview rasteriser projects every
    // splat by the header's frame (its float-to-int casts were once undefined for such files).
    rs_image img = {0};
    if (rs_pack_preview(c, 32, &img, &err) == RS_OK) rs_image_free(&img);
    free(back);
    rs_splat_destroy(c);
}

// Version 2: each chunk's CRC (where the chunk lies inside the input), then the header's.
static void fix_v2(uint8_t *b, size_t size)
{
    if (size < 624) return;
    uint32_t hs = rd(b + 8);
    if (hs < 624 || hs > size) return;
    uint32_t notes = rd(b + 584);
    size_t table = (588 + (size_t)notes + 15) / 16 * 16;
    if (notes > 8191 || table + 8 > hs - 4) return;
    uint32_t nch = rd(b + table);
    if (nch > 4096 || table + 8 + 16 * (size_t)nch > hs - 4) return;
    uint64_t off = hs;
    for (uint32_t k = 0; k < nch; k++) {
        uint8_t *e = b + table + 8 + 16 * (size_t)k;
        uint32_t bytes = rd(e + 4);
        if (off + bytes <= size) wr(e + 8, rs_crc32(0, b + off, bytes));
        off += bytes;
    }
    wr(b + hs - 4, rs_crc32(0, b, hs - 4));
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    load_one(data, size);
    if (size < 8) return 0;
    uint8_t *fixed = malloc(size);
    if (!fixed) return 0;
    memcpy(fixed, data, size);
    if (rd(data + 4) == 2) {
        fix_v2(fixed, size);
    } else {
        // Version 1: a correct CRC over everything but the last four bytes.
        uint32_t crc = rs_crc32(0, fixed, size - 4);
        wr(fixed + size - 4, crc);
    }
    if (memcmp(fixed, data, size) != 0) load_one(fixed, size);
    free(fixed);
    return 0;
}
