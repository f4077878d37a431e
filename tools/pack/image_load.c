// image_load.c — texture images for rouge-pack: PNG, JPEG, BMP or TGA by content (see import.h).
//
// One decoder per format: PNG goes through src/core/image.c (libpng, already used to write PNGs, with its
// own bomb check); JPEG through libjpeg-turbo, because Debian 12's stb_image (2.27) refuses valid
// progressive JPEGs ("unknown marker") that scans and phone photos come in; BMP and TGA through stb_image
// (Debian's libstb-dev: one public-domain header, no state), compiled here with only those two decoders.
#include "pack/import.h"

#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <jpeglib.h>
#include <jerror.h>

#define STBI_ONLY_BMP
#define STBI_ONLY_TGA
#define STBI_NO_STDIO
#define STBI_NO_LINEAR
#define STBI_NO_HDR
#define STBI_MAX_DIMENSIONS RS_IMAGE_MAX_DIM
#define STB_IMAGE_IMPLEMENTATION
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wimplicit-fallthrough"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wtype-limits"
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wdouble-promotion"
#include <stb_image.h>
#pragma GCC diagnostic pop

// A JPEG codes every 8x8 block of every component with at least one bit (a 1-bit DC difference code;
// progressive end-of-band runs skip only AC coefficients), so n bytes hold at most 8 n blocks: a header
// claiming more is a decompression bomb, refused before the decoder allocates the image.
#define JPEG_MIN_BITS_PER_BLOCK 1u

// Walks the JPEG's marker segments (and over the entropy-coded data after each scan header, where
// progressive files put further tables) and checks every Huffman table before the decoder sees it: stb
// 2.27 (Debian's, the JPEG decoder before libjpeg-turbo) wrote past its 257-entry size list when a table's
// 16 counts add up to more than 256, which the JPEG standard forbids (found by tools/fuzz/fuzz_image.c). Returns NULL or what is wrong.
static const char *jpeg_tables_bad(const uint8_t *d, size_t len)
{
    size_t i = 2;  // after SOI
    while (i + 4 <= len) {
        if (d[i] != 0xff) return "bytes between marker segments";  // a decoder would resynchronise past them
        uint8_t m = d[i + 1];
        if (m == 0xff) {  // fill byte
            i++;
            continue;
        }
        if (m == 0xd9) return NULL;  // EOI
        if (m == 0x01 || (m >= 0xd0 && m <= 0xd7)) {  // TEM, RSTn: no length
            i += 2;
            continue;
        }
        size_t seg = (size_t)d[i + 2] << 8 | d[i + 3];
        if (seg < 2 || i + 2 + seg > len) return "a marker segment runs past the end of the file";
        if (m == 0xc4) {  // DHT: tables of 1 + 16 + sum(counts) bytes
            size_t p = i + 4, end = i + 2 + seg;
            while (p < end) {
                if (p + 17 > end) return "a Huffman table is cut short";
                unsigned sum = 0;
                for (int k = 1; k <= 16; k++) sum += d[p + k];
                if (sum > 256) return "a Huffman table has more than 256 codes";
                p += 17 + sum;
                if (p > end) return "a Huffman table's symbols run past its segment";
            }
        }
        i += 2 + seg;
        if (m == 0xda) {  // SOS: skip the entropy-coded data to the next real marker
            while (i + 1 < len && !(d[i] == 0xff && d[i + 1] != 0x00 && !(d[i + 1] >= 0xd0 && d[i + 1] <= 0xd7))) i++;
        }
    }
    return NULL;
}

// libjpeg reports errors through a callback that must not return: it jumps back here with the message.
typedef struct jpeg_fail {
    struct jpeg_error_mgr mgr;
    jmp_buf back;
    char msg[JMSG_LENGTH_MAX];
    bool corrupt;  // a warning about damaged data (libjpeg would go on and fill the rest with grey)
} jpeg_fail;

static void jpeg_error_exit(j_common_ptr j)
{
    jpeg_fail *f = (jpeg_fail *)j->err;
    f->mgr.format_message(j, f->msg);
    longjmp(f->back, 1);
}

static void jpeg_emit(j_common_ptr j, int level)
{
    jpeg_fail *f = (jpeg_fail *)j->err;
    // Level -1 is a warning about the data; extraneous bytes before a marker are harmless (cameras).
    if (level < 0 && f->mgr.msg_code != JWRN_EXTRANEOUS_DATA && !f->corrupt) {
        f->corrupt = true;
        f->mgr.format_message(j, f->msg);
    }
}

static rs_result decode_jpeg(const uint8_t *data, size_t len, const char *name, rs_image *out, rs_error *err)
{
    const char *bad = jpeg_tables_bad(data, len);
    if (bad) return rs_fail(err, RS_ERR_FORMAT, "%s: bad JPEG data (%s)", name, bad);
    if (len > (size_t)UINT32_MAX) return rs_fail(err, RS_ERR_LIMIT, "%s: JPEG of %zu bytes is too large", name, len);
    struct jpeg_decompress_struct j;
    jpeg_fail f = {0};
    j.err = jpeg_std_error(&f.mgr);
    f.mgr.error_exit = jpeg_error_exit;
    f.mgr.emit_message = jpeg_emit;
    // volatile: assigned between setjmp and a longjmp back to it.
    uint8_t *volatile px = NULL;
    if (setjmp(f.back)) {
        jpeg_destroy_decompress(&j);
        free(px);
        return rs_fail(err, RS_ERR_FORMAT, "%s: bad JPEG data (%s)", name, f.msg);
    }
    jpeg_create_decompress(&j);
    jpeg_mem_src(&j, data, (unsigned long)len);
    jpeg_read_header(&j, TRUE);
    uint64_t w = j.image_width, h = j.image_height;
    rs_result r = RS_OK;
    if (w < 1 || h < 1 || w > RS_IMAGE_MAX_DIM || h > RS_IMAGE_MAX_DIM)
        r = rs_fail(err, RS_ERR_LIMIT, "%s: image is %llux%llu, larger than the %d allowed", name, (unsigned long long)w,
                    (unsigned long long)h, RS_IMAGE_MAX_DIM);
    else if (w * h > RS_IMPORT_MAX_TEXTURE_PIXELS)
        r = rs_fail(err, RS_ERR_LIMIT, "%s: image is %llux%llu = %.1f Mpx, more than the %.0f Mpx allowed", name,
                    (unsigned long long)w, (unsigned long long)h, (double)(w * h) / 1e6, RS_IMPORT_MAX_TEXTURE_PIXELS / 1e6);
    else if (((w + 7) / 8) * ((h + 7) / 8) > (uint64_t)len * 8 / JPEG_MIN_BITS_PER_BLOCK)
        r = rs_fail(err, RS_ERR_FORMAT, "%s: header claims %llux%llu pixels but the %zu-byte file cannot hold that much data",
                    name, (unsigned long long)w, (unsigned long long)h, len);
    if (r != RS_OK) {
        jpeg_destroy_decompress(&j);
        return r;
    }
    // Grey and YCbCr both come out as RGB; CMYK cannot (libjpeg says so, as an error).
    j.out_color_space = JCS_RGB;
    jpeg_start_decompress(&j);
    px = malloc((size_t)(w * h * 3));
    if (!px) {
        jpeg_destroy_decompress(&j);
        return rs_fail(err, RS_ERR_NOMEM, "%s: out of memory decoding %llux%llu", name, (unsigned long long)w,
                       (unsigned long long)h);
    }
    while (j.output_scanline < j.output_height) {
        JSAMPROW row = px + (size_t)j.output_scanline * (size_t)w * 3;
        jpeg_read_scanlines(&j, &row, 1);
    }
    jpeg_finish_decompress(&j);
    jpeg_destroy_decompress(&j);
    if (f.corrupt) {
        free(px);
        return rs_fail(err, RS_ERR_FORMAT, "%s: bad JPEG data (%s)", name, f.msg);
    }
    *out = (rs_image){.width = (int)w, .height = (int)h, .channels = 3, .pixels = px};
    return RS_OK;
}

// BMP and TGA through stb_image: the header's size is checked (stbi_info) before any pixel is allocated.
// Neither format compresses better than 128 pixels per byte (a TGA run-length packet: one count byte and
// one 8-bit pixel), so a header claiming more than that is a decompression bomb.
static rs_result decode_stb(const uint8_t *data, size_t len, const char *name, const char *what, rs_image *out, rs_error *err)
{
    if (len > (size_t)INT32_MAX) return rs_fail(err, RS_ERR_LIMIT, "%s: %s of %zu bytes is too large", name, what, len);
    int w = 0, h = 0, comp = 0;
    if (!stbi_info_from_memory(data, (int)len, &w, &h, &comp))
        return rs_fail(err, RS_ERR_FORMAT, "%s: not a readable %s file (%s)", name, what, stbi_failure_reason());
    if (w < 1 || h < 1 || w > RS_IMAGE_MAX_DIM || h > RS_IMAGE_MAX_DIM)
        return rs_fail(err, RS_ERR_LIMIT, "%s: image is %dx%d, larger than the %d allowed", name, w, h, RS_IMAGE_MAX_DIM);
    uint64_t px = (uint64_t)w * (uint64_t)h;
    if (px > RS_IMPORT_MAX_TEXTURE_PIXELS)
        return rs_fail(err, RS_ERR_LIMIT, "%s: image is %dx%d = %.1f Mpx, more than the %.0f Mpx allowed", name, w, h,
                       px / 1e6, RS_IMPORT_MAX_TEXTURE_PIXELS / 1e6);
    if (px > (uint64_t)len * 128)
        return rs_fail(err, RS_ERR_FORMAT, "%s: header claims %dx%d pixels but the %zu-byte file cannot hold that much data",
                       name, w, h, len);
    int cw, ch, cc;
    uint8_t *px8 = stbi_load_from_memory(data, (int)len, &cw, &ch, &cc, 3);
    if (!px8) {
        const char *why = stbi_failure_reason();
        if (why && !strcmp(why, "outofmem")) return rs_fail(err, RS_ERR_NOMEM, "%s: out of memory decoding %dx%d", name, w, h);
        return rs_fail(err, RS_ERR_FORMAT, "%s: bad %s data (%s)", name, what, why ? why : "?");
    }
    if (cw != w || ch != h) {
        stbi_image_free(px8);
        return rs_fail(err, RS_ERR_FORMAT, "%s: decoded size %dx%d differs from the header's %dx%d", name, cw, ch, w, h);
    }
    // Handed over as an rs_image, which rs_image_free releases with free(): stb allocates with malloc.
    *out = (rs_image){.width = w, .height = h, .channels = 3, .pixels = px8};
    return RS_OK;
}

// libjpeg decodes a JPEG cut short as if the rest were grey (with a warning): refuse files without the
// end-of-image marker, allowing trailing bytes after it (some cameras append data).
static bool jpeg_has_end(const uint8_t *d, size_t len)
{
    size_t from = len > 65536 ? len - 65536 : 2;
    for (size_t i = len - 1; i > from; i--)
        if (d[i - 1] == 0xff && d[i] == 0xd9) return true;
    return false;
}

static rs_result decode_any(const void *data, size_t len, const char *name, bool quote, rs_image *out, rs_error *err)
{
    const uint8_t *d = data;
    static const uint8_t png_sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    if (len >= 8 && !memcmp(d, png_sig, 8)) {
        // Pixel cap first (IHDR is the first chunk: width and height at bytes 16..23), then libpng's own
        // checks (sides, and what the compressed bytes can hold).
        if (len >= 24) {
            uint64_t w = (uint64_t)d[16] << 24 | (uint64_t)d[17] << 16 | (uint64_t)d[18] << 8 | d[19];
            uint64_t h = (uint64_t)d[20] << 24 | (uint64_t)d[21] << 16 | (uint64_t)d[22] << 8 | d[23];
            if (w <= RS_IMAGE_MAX_DIM && h <= RS_IMAGE_MAX_DIM && w * h > RS_IMPORT_MAX_TEXTURE_PIXELS)
                return rs_fail(err, RS_ERR_LIMIT, "%s: image is %llux%llu = %.1f Mpx, more than the %.0f Mpx allowed", name,
                               (unsigned long long)w, (unsigned long long)h, (double)(w * h) / 1e6,
                               RS_IMPORT_MAX_TEXTURE_PIXELS / 1e6);
        }
        return rs_image_read_png_memory(data, len, name, out, err);
    }
    if (len >= 3 && d[0] == 0xff && d[1] == 0xd8 && d[2] == 0xff) {
        if (!jpeg_has_end(d, len))
            return rs_fail(err, RS_ERR_FORMAT, "%s: JPEG is truncated (no end-of-image marker in its %zu bytes)", name, len);
        return decode_jpeg(d, len, name, out, err);
    }
    if (len >= 2 && d[0] == 'B' && d[1] == 'M') return decode_stb(d, len, name, "BMP", out, err);
    // TGA has no signature: stb's header test (image type, colour map, sizes and depth) decides.
    int w, h, comp;
    if (len >= 18 && len <= (size_t)INT32_MAX && stbi_info_from_memory(d, (int)len, &w, &h, &comp))
        return decode_stb(d, len, name, "TGA", out, err);
    if (len == 0) return rs_fail(err, RS_ERR_FORMAT, "%s: not a PNG, JPEG, BMP or TGA file (empty)", name);
    if (!quote) return rs_fail(err, RS_ERR_FORMAT, "%s: not a PNG, JPEG, BMP or TGA file", name);
    char hex[16] = "";
    for (size_t i = 0; i < RS_MIN(len, (size_t)4); i++) snprintf(hex + 3 * i, sizeof hex - 3 * i, "%02x ", d[i]);
    hex[strlen(hex) - 1] = 0;
    return rs_fail(err, RS_ERR_FORMAT, "%s: not a PNG, JPEG, BMP or TGA file (starts %s)", name, hex);
}

rs_result rs_image_decode_any(const void *data, size_t len, const char *name, rs_image *out, rs_error *err)
{
    return decode_any(data, len, name, true, out, err);
}

// `quote`: the first bytes of a file that is not an image help the user who named it; a file a model
// names is not the user's, and its bytes must not leak into a message.
static rs_result load_any(const char *path, bool quote, rs_image *out, rs_error *err)
{
    void *data;
    size_t len;
    rs_result r = rs_file_read_all(path, RS_IMPORT_MAX_FILE, &data, &len, err);
    if (r != RS_OK) return r;
    r = decode_any(data, len, path, quote, out, err);
    free(data);
    return r;
}

rs_result rs_image_load_any(const char *path, rs_image *out, rs_error *err)
{
    return load_any(path, true, out, err);
}

rs_result rs_image_load_referenced(const char *path, rs_image *out, rs_error *err)
{
    return load_any(path, false, out, err);
}
