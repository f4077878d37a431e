// test_image.c — PNG I/O and the image metrics (src/core/image.c).
#define _POSIX_C_SOURCE 200809L
#include "support/harness.h"

#include <errno.h>
#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

// ---------------------------------------------------------------------------------------------------
// Helpers

static const char *tmp_path(const char *name)
{
    static char buf[4][1024];
    static int slot;
    char *p = buf[slot++ % 4];
    snprintf(p, sizeof buf[0], "%s/image_%s", rs_test_out_dir(), name);
    return p;
}

static uint64_t rng_state;

static uint64_t rng_next(void)
{
    // xorshift64*: deterministic, so every run sees the same images.
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return rng_state * 2685821657736338717ull;
}

static double rng_uniform(void)
{
    return ((rng_next() >> 11) + 0.5) * (1.0 / 9007199254740992.0);
}

static double rng_gauss(void)
{
    return sqrt(-2.0 * log(rng_uniform())) * cos(2.0 * 3.14159265358979323846 * rng_uniform());
}

// A textured test image with values in [lo, hi] on every channel (alpha, if any, varies too).
static bool make_pattern(int w, int h, int channels, int lo, int hi, rs_image *img)
{
    rs_error err = {0};
    if (rs_image_create(w, h, channels, img, &err) != RS_OK) return false;
    rng_state = 0x9e3779b97f4a7c15ull ^ (uint64_t)(w * 31 + h);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int c = 0; c < channels; c++) {
                double v = 0.5 + 0.3 * sin(0.21 * x + c) * cos(0.17 * y - c) + 0.15 * (rng_uniform() - 0.5);
                img->pixels[((size_t)y * w + x) * channels + c] = (uint8_t)(lo + (hi - lo) * RS_CLAMP(v, 0.0, 1.0));
            }
    return true;
}

static bool copy_image(const rs_image *src, rs_image *dst)
{
    rs_error err = {0};
    if (rs_image_create(src->width, src->height, src->channels, dst, &err) != RS_OK) return false;
    memcpy(dst->pixels, src->pixels, (size_t)src->width * src->height * src->channels);
    return true;
}

static bool same_pixels(const rs_image *a, const rs_image *b)
{
    return a->width == b->width && a->height == b->height && a->channels == b->channels &&
           memcmp(a->pixels, b->pixels, (size_t)a->width * a->height * a->channels) == 0;
}

static bool file_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

static bool write_bytes(const char *path, const void *data, size_t len)
{
    FILE *f = fopen(path, "wb");
    if (!f) return false;
    bool ok = fwrite(data, 1, len, f) == len;
    return fclose(f) == 0 && ok;
}

static bool read_bytes(const char *path, uint8_t **data, size_t *len)
{
    rs_error err = {0};
    return rs_file_read_all(path, 1u << 24, (void **)data, len, &err) == RS_OK;
}

// Writes a PNG of any colour type straight through libpng, bypassing the module under test.
typedef struct raw_png {
    int width, height, color_type, bit_depth, interlace;
    const uint8_t *rows;            // tightly packed rows in PNG sample order (16-bit big-endian)
    const png_color *palette;
    int palette_len;
    const png_byte *trns;           // palette alpha
    int trns_len;
} raw_png;

static bool write_raw_png(const char *path, const raw_png *d)
{
    FILE *f = fopen(path, "wb");
    if (!f) return false;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png_create_info_struct(png);
    png_bytep *rows = calloc((size_t)d->height, sizeof *rows);
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        free(rows);
        fclose(f);
        return false;
    }
    png_init_io(png, f);
    png_set_IHDR(png, info, (png_uint_32)d->width, (png_uint_32)d->height, d->bit_depth, d->color_type,
                 d->interlace, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    if (d->palette) png_set_PLTE(png, info, d->palette, d->palette_len);
    if (d->trns) png_set_tRNS(png, info, d->trns, d->trns_len, NULL);
    png_write_info(png, info);
    size_t stride = png_get_rowbytes(png, info);
    for (int y = 0; y < d->height; y++) rows[y] = (png_bytep)d->rows + (size_t)y * stride;
    png_write_image(png, rows);
    png_write_end(png, NULL);
    png_destroy_write_struct(&png, &info);
    free(rows);
    return fclose(f) == 0;
}

static uint32_t crc32_png(const uint8_t *p, size_t n)
{
    uint32_t c = 0xffffffffu;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int k = 0; k < 8; k++) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
    }
    return c ^ 0xffffffffu;
}

static size_t put_be32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v >> 24);
    p[1] = (uint8_t)(v >> 16);
    p[2] = (uint8_t)(v >> 8);
    p[3] = (uint8_t)v;
    return 4;
}

// Appends a chunk with a correct CRC; returns the new length.
static size_t put_chunk(uint8_t *buf, size_t at, const char *type, const uint8_t *data, uint32_t len)
{
    at += put_be32(buf + at, len);
    memcpy(buf + at, type, 4);
    if (len) memcpy(buf + at + 4, data, len);
    at += put_be32(buf + at + 4 + len, crc32_png(buf + at, 4 + len)) + 4 + len;
    return at;
}

// A hand-made PNG whose header claims w x h 8-bit grey pixels followed by a tiny IDAT.
static size_t craft_png(uint8_t *buf, uint32_t w, uint32_t h)
{
    static const uint8_t sig[8] = { 137, 80, 78, 71, 13, 10, 26, 10 };
    memcpy(buf, sig, 8);
    uint8_t ihdr[13] = { 0 };
    put_be32(ihdr, w);
    put_be32(ihdr + 4, h);
    ihdr[8] = 8;  // bit depth; colour type 0 (grey), compression, filter and interlace 0
    size_t n = put_chunk(buf, 8, "IHDR", ihdr, 13);
    // zlib stream of a single empty stored block: far too little data for the header's promise.
    static const uint8_t idat[] = { 0x78, 0x01, 0x01, 0x00, 0x00, 0xff, 0xff, 0x00, 0x00, 0x00, 0x01 };
    n = put_chunk(buf, n, "IDAT", idat, sizeof idat);
    return put_chunk(buf, n, "IEND", NULL, 0);
}

static double compare_ssim(const rs_image *a, const rs_image *b)
{
    rs_error err = {0};
    rs_image_metrics m;
    if (rs_image_compare(a, b, 8, &m, &err) != RS_OK) return NAN;
    return m.ssim;
}

// ---------------------------------------------------------------------------------------------------
// Create / free

static void test_create_rejects_bad_sizes_and_channels(void)
{
    rs_error err = {0};
    rs_image img = { .width = 7 };
    RS_CHECK(rs_image_create(0, 4, 3, &img, &err) == RS_ERR_ARG, "width 0 accepted");
    RS_CHECK(rs_image_create(4, -1, 3, &img, &err) == RS_ERR_ARG, "negative height accepted");
    RS_CHECK(rs_image_create(RS_IMAGE_MAX_DIM + 1, 1, 3, &img, &err) == RS_ERR_ARG, "width over limit accepted");
    RS_CHECK(rs_image_create(4, 4, 2, &img, &err) == RS_ERR_ARG, "2 channels accepted");
    RS_CHECK(strstr(err.msg, "channels") != NULL, "message does not name channels: %s", err.msg);
    RS_CHECK(img.width == 7 && img.pixels == NULL, "output touched on failure");
    RS_REQUIRE(rs_image_create(5, 3, 4, &img, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(img.width == 5 && img.height == 3 && img.channels == 4, "wrong shape");
    bool zero = true;
    for (int i = 0; i < 5 * 3 * 4; i++) zero = zero && img.pixels[i] == 0;
    RS_CHECK(zero, "pixels not zeroed");
    rs_image_free(&img);
    RS_CHECK(img.pixels == NULL && img.width == 0, "free does not reset the image");
    rs_image_free(&img);
    rs_image_free(NULL);
}

// ---------------------------------------------------------------------------------------------------
// Metrics

static void test_identical_images_give_infinite_psnr_and_ssim_exactly_one(void)
{
    rs_image a = {0}, b = {0};
    RS_REQUIRE(make_pattern(64, 48, 3, 0, 255, &a) && copy_image(&a, &b), "setup");
    rs_error err = {0};
    rs_image_metrics m;
    RS_CHECK(rs_image_compare(&a, &b, 0, &m, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(isinf(m.psnr) && m.psnr > 0, "psnr %g", m.psnr);
    RS_CHECK(m.ssim == 1.0, "ssim %.17g", m.ssim);
    RS_CHECK(m.max_abs == 0 && m.mean_abs == 0.0 && m.delta_e == 0.0 && m.frac_over == 0.0,
             "max %d mean %g de %g frac %g", m.max_abs, m.mean_abs, m.delta_e, m.frac_over);
    rs_image_free(&a);
    rs_image_free(&b);
}

static void test_uniform_offset_gives_exact_psnr_and_abs_errors(void)
{
    static const int offsets[] = { 1, 3, 17, 100 };
    for (size_t k = 0; k < RS_COUNT_OF(offsets); k++) {
        int d = offsets[k];
        rs_image a = {0}, b = {0};
        RS_REQUIRE(make_pattern(40, 30, 3, 0, 255 - d, &a) && copy_image(&a, &b), "setup");
        for (size_t i = 0; i < (size_t)40 * 30 * 3; i++) b.pixels[i] = (uint8_t)(b.pixels[i] + d);
        rs_error err = {0};
        rs_image_metrics m;
        RS_CHECK(rs_image_compare(&a, &b, 255, &m, &err) == RS_OK, "%s", err.msg);
        double want = 20.0 * log10(255.0 / d);
        RS_CHECK(fabs(m.psnr - want) < 1e-9, "offset %d: psnr %.12f, want %.12f", d, m.psnr, want);
        RS_CHECK(m.max_abs == d && m.mean_abs == d, "offset %d: max %d mean %g", d, m.max_abs, m.mean_abs);
        RS_CHECK(m.frac_over == 0.0, "offset %d: frac_over %g at threshold 255", d, m.frac_over);
        RS_CHECK(m.ssim < 1.0 && m.ssim > 0.0, "offset %d: ssim %g", d, m.ssim);
        rs_image_free(&a);
        rs_image_free(&b);
    }
}

static void test_one_changed_pixel_gives_frac_over_of_one_pixel(void)
{
    rs_image a = {0}, b = {0};
    RS_REQUIRE(make_pattern(32, 24, 3, 0, 200, &a) && copy_image(&a, &b), "setup");
    b.pixels[(5 * 32 + 7) * 3 + 1] += 20;
    rs_error err = {0};
    rs_image_metrics m;
    RS_REQUIRE(rs_image_compare(&a, &b, 8, &m, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(m.frac_over == 1.0 / (32 * 24), "frac_over %.17g", m.frac_over);
    RS_CHECK(m.max_abs == 20, "max_abs %d", m.max_abs);
    RS_CHECK(fabs(m.mean_abs - 20.0 / (32 * 24 * 3)) < 1e-15, "mean_abs %g", m.mean_abs);
    // The threshold is strict: a difference equal to it does not count.
    RS_REQUIRE(rs_image_compare(&a, &b, 20, &m, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(m.frac_over == 0.0, "difference equal to the threshold counted: %g", m.frac_over);
    RS_REQUIRE(rs_image_compare(&a, &b, 19, &m, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(m.frac_over == 1.0 / (32 * 24), "threshold 19: frac_over %g", m.frac_over);
    rs_image_free(&a);
    rs_image_free(&b);
}

static void test_compare_ignores_alpha(void)
{
    rs_image rgba = {0}, rgb = {0};
    RS_REQUIRE(make_pattern(16, 16, 4, 0, 255, &rgba), "setup");
    rs_error err = {0};
    RS_REQUIRE(rs_image_create(16, 16, 3, &rgb, &err) == RS_OK, "%s", err.msg);
    for (int i = 0; i < 16 * 16; i++) memcpy(rgb.pixels + i * 3, rgba.pixels + i * 4, 3);
    rs_image_metrics m;
    RS_REQUIRE(rs_image_compare(&rgba, &rgb, 0, &m, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(isinf(m.psnr) && m.ssim == 1.0 && m.max_abs == 0, "alpha counted: psnr %g max %d", m.psnr, m.max_abs);
    rs_image_free(&rgba);
    rs_image_free(&rgb);
}

static void test_compare_and_diff_reject_size_mismatch_naming_both_sizes(void)
{
    rs_image a = {0}, b = {0}, d = {0};
    RS_REQUIRE(make_pattern(20, 10, 3, 0, 255, &a) && make_pattern(10, 20, 3, 0, 255, &b), "setup");
    rs_error err = {0};
    rs_image_metrics m = { .psnr = 42.0 };
    RS_CHECK(rs_image_compare(&a, &b, 8, &m, &err) == RS_ERR_ARG, "mismatch accepted");
    RS_CHECK(strstr(err.msg, "20x10") && strstr(err.msg, "10x20"), "message: %s", err.msg);
    RS_CHECK(m.psnr == 42.0, "metrics touched on failure");
    RS_CHECK(rs_image_diff(&a, &b, &d, &err) == RS_ERR_ARG && d.pixels == NULL, "diff accepted a mismatch");
    rs_image empty = {0};
    RS_CHECK(rs_image_compare(&a, &empty, 8, &m, &err) == RS_ERR_ARG, "empty image accepted");
    rs_image_free(&a);
    rs_image_free(&b);
}

// Sharma, Wu & Dalal (2005), Table 1: L1 a1 b1, L2 a2 b2, published delta E00 (4 decimals).
static const double sharma[34][7] = {
    { 50.0000, 2.6772, -79.7751, 50.0000, 0.0000, -82.7485, 2.0425 },
    { 50.0000, 3.1571, -77.2803, 50.0000, 0.0000, -82.7485, 2.8615 },
    { 50.0000, 2.8361, -74.0200, 50.0000, 0.0000, -82.7485, 3.4412 },
    { 50.0000, -1.3802, -84.2814, 50.0000, 0.0000, -82.7485, 1.0000 },
    { 50.0000, -1.1848, -84.8006, 50.0000, 0.0000, -82.7485, 1.0000 },
    { 50.0000, -0.9009, -85.5211, 50.0000, 0.0000, -82.7485, 1.0000 },
    { 50.0000, 0.0000, 0.0000, 50.0000, -1.0000, 2.0000, 2.3669 },
    { 50.0000, -1.0000, 2.0000, 50.0000, 0.0000, 0.0000, 2.3669 },
    { 50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0009, 7.1792 },
    { 50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0010, 7.1792 },
    { 50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0011, 7.2195 },
    { 50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0012, 7.2195 },
    { 50.0000, -0.0010, 2.4900, 50.0000, 0.0009, -2.4900, 4.8045 },
    { 50.0000, -0.0010, 2.4900, 50.0000, 0.0010, -2.4900, 4.8045 },
    { 50.0000, -0.0010, 2.4900, 50.0000, 0.0011, -2.4900, 4.7461 },
    { 50.0000, 2.5000, 0.0000, 50.0000, 0.0000, -2.5000, 4.3065 },
    { 50.0000, 2.5000, 0.0000, 73.0000, 25.0000, -18.0000, 27.1492 },
    { 50.0000, 2.5000, 0.0000, 61.0000, -5.0000, 29.0000, 22.8977 },
    { 50.0000, 2.5000, 0.0000, 56.0000, -27.0000, -3.0000, 31.9030 },
    { 50.0000, 2.5000, 0.0000, 58.0000, 24.0000, 15.0000, 19.4535 },
    { 50.0000, 2.5000, 0.0000, 50.0000, 3.1736, 0.5854, 1.0000 },
    { 50.0000, 2.5000, 0.0000, 50.0000, 3.2972, 0.0000, 1.0000 },
    { 50.0000, 2.5000, 0.0000, 50.0000, 1.8634, 0.5757, 1.0000 },
    { 50.0000, 2.5000, 0.0000, 50.0000, 3.2592, 0.3350, 1.0000 },
    { 60.2574, -34.0099, 36.2677, 60.4626, -34.1751, 39.4387, 1.2644 },
    { 63.0109, -31.0961, -5.8663, 62.8187, -29.7946, -4.0864, 1.2630 },
    { 61.2901, 3.7196, -5.3901, 61.4292, 2.2480, -4.9620, 1.8731 },
    { 35.0831, -44.1164, 3.7933, 35.0232, -40.0716, 1.5901, 1.8645 },
    { 22.7233, 20.0904, -46.6940, 23.0331, 14.9730, -42.5619, 2.0373 },
    { 36.4612, 47.8580, 18.3852, 36.2715, 50.5065, 21.2231, 1.4146 },
    { 90.8027, -2.0831, 1.4410, 91.1528, -1.6435, 0.0447, 1.4441 },
    { 90.9257, -0.5406, -0.9208, 88.6381, -0.8985, -0.7239, 1.5381 },
    { 6.7747, -0.2908, -2.4247, 5.8714, -0.0985, -2.2286, 0.6377 },
    { 2.0776, 0.0795, -1.1350, 0.9033, -0.0636, -0.5514, 0.9082 },
};

static void test_ciede2000_matches_sharma_published_pairs(void)
{
    for (int i = 0; i < 34; i++) {
        const double *r = sharma[i];
        double d12 = rs_ciede2000(r, r + 3), d21 = rs_ciede2000(r + 3, r);
        RS_CHECK(fabs(d12 - r[6]) < 1e-4, "pair %d: %.6f, published %.4f", i + 1, d12, r[6]);
        RS_CHECK(fabs(d21 - r[6]) < 1e-4, "pair %d swapped: %.6f, published %.4f", i + 1, d21, r[6]);
        RS_CHECK(rs_ciede2000(r, r) == 0.0, "pair %d: nonzero against itself", i + 1);
    }
}

static void test_srgb_to_lab_known_colours(void)
{
    struct { uint8_t rgb[3]; double lab[3]; } cases[] = {
        { { 255, 255, 255 }, { 100.0, 0.0, 0.0 } },
        { { 0, 0, 0 }, { 0.0, 0.0, 0.0 } },
        // Published sRGB -> Lab (D65) values (Lindbloom's calculator).
        { { 255, 0, 0 }, { 53.2408, 80.0925, 67.2032 } },
        { { 0, 0, 255 }, { 32.2970, 79.1875, -107.8602 } },
        { { 128, 128, 128 }, { 53.5850, 0.0, 0.0 } },
    };
    for (size_t i = 0; i < RS_COUNT_OF(cases); i++) {
        double lab[3];
        rs_srgb8_to_lab(cases[i].rgb, lab);
        for (int c = 0; c < 3; c++)
            RS_CHECK(fabs(lab[c] - cases[i].lab[c]) < 0.01, "rgb %d,%d,%d: Lab %.4f %.4f %.4f", cases[i].rgb[0],
                     cases[i].rgb[1], cases[i].rgb[2], lab[0], lab[1], lab[2]);
    }
}

static void test_delta_e_is_mean_ciede2000_over_pixels(void)
{
    rs_error err = {0};
    rs_image a = {0}, b = {0};
    RS_REQUIRE(rs_image_create(8, 4, 3, &a, &err) == RS_OK && rs_image_create(8, 4, 4, &b, &err) == RS_OK, "setup");
    const uint8_t ca[3] = { 200, 120, 90 }, cb[3] = { 190, 130, 95 };
    // Top half differs, bottom half is equal (zero delta E).
    for (int i = 0; i < 32; i++) {
        memcpy(a.pixels + i * 3, ca, 3);
        memcpy(b.pixels + i * 4, i < 16 ? cb : ca, 3);
    }
    double la[3], lb[3];
    rs_srgb8_to_lab(ca, la);
    rs_srgb8_to_lab(cb, lb);
    double want = 0.5 * rs_ciede2000(la, lb);
    rs_image_metrics m;
    RS_REQUIRE(rs_image_compare(&a, &b, 8, &m, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(want > 1.0 && fabs(m.delta_e - want) < 1e-12, "delta_e %.15f, want %.15f", m.delta_e, want);
    RS_CHECK(m.frac_over == 0.5 && m.max_abs == 10, "frac_over %g max %d", m.frac_over, m.max_abs);
    rs_image_free(&a);
    rs_image_free(&b);
}

// Mean SSIM computed the slow, obvious way: a full 2-D window at every valid position.
static double ssim_direct(const rs_image *a, const rs_image *b)
{
    int w = a->width, h = a->height;
    int kx = RS_MIN(11, w), ky = RS_MIN(11, h);
    if (kx % 2 == 0) kx--;
    if (ky % 2 == 0) ky--;
    double g[11][11], sum = 0;
    for (int j = 0; j < ky; j++)
        for (int i = 0; i < kx; i++) {
            double dx = i - (kx - 1) / 2.0, dy = j - (ky - 1) / 2.0;
            sum += g[j][i] = exp(-(dx * dx + dy * dy) / (2 * 1.5 * 1.5));
        }
    const double C1 = 6.5025, C2 = 58.5225;
    double total = 0;
    int n = 0;
    for (int y = 0; y + ky <= h; y++)
        for (int x = 0; x + kx <= w; x++) {
            double ux = 0, uy = 0, sxx = 0, syy = 0, sxy = 0;
            for (int j = 0; j < ky; j++)
                for (int i = 0; i < kx; i++) {
                    const uint8_t *p = a->pixels + ((size_t)(y + j) * w + x + i) * a->channels;
                    const uint8_t *q = b->pixels + ((size_t)(y + j) * w + x + i) * b->channels;
                    double u = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
                    double v = 0.2126 * q[0] + 0.7152 * q[1] + 0.0722 * q[2];
                    double t = g[j][i] / sum;
                    ux += t * u;
                    uy += t * v;
                    sxx += t * u * u;
                    syy += t * v * v;
                    sxy += t * u * v;
                }
            double vx = sxx - ux * ux, vy = syy - uy * uy, cxy = sxy - ux * uy;
            total += (2 * ux * uy + C1) * (2 * cxy + C2) / ((ux * ux + uy * uy + C1) * (vx + vy + C2));
            n++;
        }
    return total / n;
}

static void test_ssim_matches_direct_windowed_formula(void)
{
    static const int sizes[][2] = { { 11, 11 }, { 23, 17 }, { 40, 12 }, { 7, 30 }, { 6, 4 }, { 1, 1 } };
    for (size_t k = 0; k < RS_COUNT_OF(sizes); k++) {
        int w = sizes[k][0], h = sizes[k][1];
        rs_image a = {0}, b = {0};
        RS_REQUIRE(make_pattern(w, h, 3, 0, 255, &a) && copy_image(&a, &b), "setup");
        rng_state = 12345;
        for (size_t i = 0; i < (size_t)w * h * 3; i++)
            b.pixels[i] = (uint8_t)RS_CLAMP(b.pixels[i] + (int)lround(20 * rng_gauss()), 0, 255);
        double fast = compare_ssim(&a, &b), slow = ssim_direct(&a, &b);
        RS_CHECK(fabs(fast - slow) < 1e-12 && fast < 1.0, "%dx%d: ssim %.15f, direct %.15f", w, h, fast, slow);
        rs_image_free(&a);
        rs_image_free(&b);
    }
}

static void test_ssim_decreases_with_noise_and_is_symmetric(void)
{
    static const double sigmas[] = { 1, 2, 4, 8, 16, 32, 64 };
    rs_image a = {0}, b = {0};
    RS_REQUIRE(make_pattern(128, 96, 3, 30, 225, &a) && copy_image(&a, &b), "setup");
    double prev = 1.0;
    for (size_t k = 0; k < RS_COUNT_OF(sigmas); k++) {
        rng_state = 777;  // the same noise pattern, scaled
        for (size_t i = 0; i < (size_t)128 * 96 * 3; i++)
            b.pixels[i] = (uint8_t)RS_CLAMP(a.pixels[i] + (int)lround(sigmas[k] * rng_gauss()), 0, 255);
        double ab = compare_ssim(&a, &b), ba = compare_ssim(&b, &a);
        RS_CHECK(ab < prev, "sigma %g: ssim %.6f not below %.6f", sigmas[k], ab, prev);
        RS_CHECK(ab == ba, "sigma %g: ssim(a,b) %.17g != ssim(b,a) %.17g", sigmas[k], ab, ba);
        prev = ab;
    }
    RS_CHECK(prev < 0.5, "heavy noise still ssim %.4f", prev);
    rs_image_free(&a);
    rs_image_free(&b);
}

static void test_ssim_handles_images_smaller_than_window(void)
{
    static const int sizes[][2] = { { 1, 1 }, { 2, 2 }, { 10, 3 }, { 3, 100 } };
    for (size_t k = 0; k < RS_COUNT_OF(sizes); k++) {
        rs_image a = {0}, b = {0};
        RS_REQUIRE(make_pattern(sizes[k][0], sizes[k][1], 3, 0, 200, &a) && copy_image(&a, &b), "setup");
        double same = compare_ssim(&a, &b);
        for (size_t i = 0; i < (size_t)sizes[k][0] * sizes[k][1] * 3; i++) b.pixels[i] = (uint8_t)(255 - b.pixels[i]);
        double diff = compare_ssim(&a, &b);
        RS_CHECK(same == 1.0, "%dx%d: identical ssim %.17g", sizes[k][0], sizes[k][1], same);
        RS_CHECK(isfinite(diff) && diff < 1.0 && diff > -1.0, "%dx%d: inverted ssim %g", sizes[k][0], sizes[k][1], diff);
        rs_image_free(&a);
        rs_image_free(&b);
    }
}

static void test_diff_amplifies_by_four_and_clamps(void)
{
    rs_error err = {0};
    rs_image a = {0}, b = {0}, d = {0};
    RS_REQUIRE(rs_image_create(3, 1, 4, &a, &err) == RS_OK && rs_image_create(3, 1, 3, &b, &err) == RS_OK, "setup");
    const uint8_t pa[12] = { 10, 20, 30, 255, 100, 100, 100, 0, 0, 255, 7, 9 };
    const uint8_t pb[9] = { 12, 20, 25, 50, 200, 100, 255, 0, 7 };
    memcpy(a.pixels, pa, sizeof pa);
    memcpy(b.pixels, pb, sizeof pb);
    RS_REQUIRE(rs_image_diff(&a, &b, &d, &err) == RS_OK, "%s", err.msg);
    const uint8_t want[9] = { 8, 0, 20, 200, 255, 0, 255, 255, 0 };
    RS_CHECK(d.channels == 3 && d.width == 3 && memcmp(d.pixels, want, 9) == 0,
             "diff %d %d %d / %d %d %d / %d %d %d", d.pixels[0], d.pixels[1], d.pixels[2], d.pixels[3], d.pixels[4],
             d.pixels[5], d.pixels[6], d.pixels[7], d.pixels[8]);
    rs_image_free(&a);
    rs_image_free(&b);
    rs_image_free(&d);
}

// A 2x2 block of black and white averages to half the light (sRGB 188, not 128: a box filter on the encoded
// values would draw every anti-aliased edge too dark), a uniform block to itself, alpha as is; a size that
// is not a multiple of the factor is refused with both numbers.
static void test_downsample_averages_light_not_codes(void)
{
    rs_error err = {0};
    rs_image a = {0}, d = {0};
    RS_REQUIRE(rs_image_create(4, 2, 4, &a, &err) == RS_OK, "setup");
    const uint8_t px[32] = {0, 0, 0, 0,        255, 255, 255, 255, 77, 77, 77, 10, 77, 77, 77, 10,
                            255, 255, 255, 255, 0, 0, 0, 0,         77, 77, 77, 30, 77, 77, 77, 30};
    memcpy(a.pixels, px, sizeof px);
    RS_REQUIRE(rs_image_downsample(&a, 2, &d, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(d.width == 2 && d.height == 1 && d.channels == 4, "size %dx%dx%d", d.width, d.height, d.channels);
    const uint8_t want[8] = {188, 188, 188, 128, 77, 77, 77, 20};
    RS_CHECK(memcmp(d.pixels, want, sizeof want) == 0, "got %d %d %d %d / %d %d %d %d", d.pixels[0], d.pixels[1],
             d.pixels[2], d.pixels[3], d.pixels[4], d.pixels[5], d.pixels[6], d.pixels[7]);
    rs_image_free(&d);
    RS_CHECK(rs_image_downsample(&a, 3, &d, &err) != RS_OK && strstr(err.msg, "4x2") && strstr(err.msg, "3"),
             "a 4x2 image by 3: '%s'", err.msg);
    RS_CHECK(d.pixels == NULL, "an image was made on failure");
    rs_image_free(&a);
}

// ---------------------------------------------------------------------------------------------------
// PNG I/O

static void round_trip(int channels, const char *name)
{
    rs_image a = {0}, b = {0};
    RS_REQUIRE(make_pattern(37, 29, channels, 0, 255, &a), "setup");
    const char *path = tmp_path(name);
    rs_error err = {0};
    RS_REQUIRE(rs_image_write_png(path, &a, &err) == RS_OK, "%s", err.msg);
    RS_REQUIRE(rs_image_read_png(path, &b, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(same_pixels(&a, &b), "%s: pixels changed (%dx%dx%d read back)", name, b.width, b.height, b.channels);
    char tmp[1100];
    snprintf(tmp, sizeof tmp, "%s.tmp.%ld", path, (long)getpid());
    RS_CHECK(!file_exists(tmp), "temp file %s left behind", tmp);
    rs_image_free(&a);
    rs_image_free(&b);
}

static void test_png_round_trip_rgb_is_lossless(void)
{
    round_trip(3, "rt_rgb.png");
}

static void test_png_round_trip_rgba_is_lossless(void)
{
    round_trip(4, "rt_rgba.png");
}

// Writes `d` with libpng, reads it with the module, and compares with the expected 8-bit pixels.
static void check_decodes_to(const char *name, const raw_png *d, int want_channels, const uint8_t *want)
{
    const char *path = tmp_path(name);
    RS_REQUIRE(write_raw_png(path, d), "%s: could not write the fixture", name);
    rs_image img = {0};
    rs_error err = {0};
    RS_REQUIRE(rs_image_read_png(path, &img, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(img.width == d->width && img.height == d->height && img.channels == want_channels,
             "%s: read as %dx%dx%d", name, img.width, img.height, img.channels);
    if (img.channels == want_channels) {
        size_t n = (size_t)img.width * img.height * want_channels;
        size_t bad = n;
        for (size_t i = 0; i < n && bad == n; i++)
            if (img.pixels[i] != want[i]) bad = i;
        RS_CHECK(bad == n, "%s: sample %zu is %d, want %d", name, bad, bad < n ? img.pixels[bad] : 0,
                 bad < n ? want[bad] : 0);
    }
    rs_image_free(&img);
}

static void test_png_reads_palette_as_rgb(void)
{
    const png_color pal[3] = { { 255, 0, 0 }, { 0, 128, 0 }, { 10, 20, 30 } };
    const uint8_t idx[6] = { 0, 1, 2, 2, 1, 0 };
    const uint8_t want[18] = { 255, 0, 0, 0, 128, 0, 10, 20, 30, 10, 20, 30, 0, 128, 0, 255, 0, 0 };
    raw_png d = { .width = 3, .height = 2, .color_type = PNG_COLOR_TYPE_PALETTE, .bit_depth = 8, .rows = idx,
                  .palette = pal, .palette_len = 3 };
    check_decodes_to("palette.png", &d, 3, want);
}

static void test_png_reads_4bit_palette_with_transparency_as_rgba(void)
{
    const png_color pal[2] = { { 1, 2, 3 }, { 200, 100, 50 } };
    const png_byte alpha[2] = { 0, 128 };
    const uint8_t packed[2] = { 0x01, 0x10 };  // 4-bit indices: row 0 = 0,1; row 1 = 1,0
    const uint8_t want[16] = { 1, 2, 3, 0, 200, 100, 50, 128, 200, 100, 50, 128, 1, 2, 3, 0 };
    raw_png d = { .width = 2, .height = 2, .color_type = PNG_COLOR_TYPE_PALETTE, .bit_depth = 4, .rows = packed,
                  .palette = pal, .palette_len = 2, .trns = alpha, .trns_len = 2 };
    check_decodes_to("palette4_trns.png", &d, 4, want);
}

static void test_png_reads_1bit_grey_as_rgb(void)
{
    const uint8_t packed[2] = { 0xa0, 0x40 };  // row 0 = 1,0,1; row 1 = 0,1,0
    const uint8_t want[18] = { 255, 255, 255, 0, 0, 0, 255, 255, 255, 0, 0, 0, 255, 255, 255, 0, 0, 0 };
    raw_png d = { .width = 3, .height = 2, .color_type = PNG_COLOR_TYPE_GRAY, .bit_depth = 1, .rows = packed };
    check_decodes_to("grey1.png", &d, 3, want);
}

static void test_png_reads_grey_alpha_as_rgba(void)
{
    const uint8_t ga[4] = { 17, 255, 200, 3 };
    const uint8_t want[8] = { 17, 17, 17, 255, 200, 200, 200, 3 };
    raw_png d = { .width = 2, .height = 1, .color_type = PNG_COLOR_TYPE_GRAY_ALPHA, .bit_depth = 8, .rows = ga };
    check_decodes_to("grey_alpha.png", &d, 4, want);
}

static void test_png_reads_16bit_rgb_and_rgba_as_8bit(void)
{
    // Samples v * 257 map back to exactly v; others round to the nearest 8-bit value (v / 257), so
    // 0x10a0 becomes 0x11 where dropping the low byte would give 0x10.
    const uint8_t rgb16[12] = { 0x12, 0x12, 0xff, 0xff, 0x00, 0x00, 0x10, 0xa0, 0x7f, 0x00, 0x80, 0xff };
    const uint8_t want_rgb[6] = { 0x12, 0xff, 0x00, 0x11, 0x7f, 0x80 };
    raw_png d = { .width = 2, .height = 1, .color_type = PNG_COLOR_TYPE_RGB, .bit_depth = 16, .rows = rgb16 };
    check_decodes_to("rgb16.png", &d, 3, want_rgb);
    const uint8_t rgba16[8] = { 0x40, 0x40, 0x00, 0x00, 0xc8, 0xc8, 0x64, 0x64 };
    const uint8_t want_rgba[4] = { 0x40, 0x00, 0xc8, 0x64 };
    raw_png e = { .width = 1, .height = 1, .color_type = PNG_COLOR_TYPE_RGB_ALPHA, .bit_depth = 16, .rows = rgba16 };
    check_decodes_to("rgba16.png", &e, 4, want_rgba);
}

static void test_png_reads_interlaced_as_plain_rows(void)
{
    rs_image a = {0};
    RS_REQUIRE(make_pattern(19, 13, 3, 0, 255, &a), "setup");
    raw_png d = { .width = 19, .height = 13, .color_type = PNG_COLOR_TYPE_RGB, .bit_depth = 8,
                  .interlace = PNG_INTERLACE_ADAM7, .rows = a.pixels };
    check_decodes_to("adam7.png", &d, 3, a.pixels);
    rs_image_free(&a);
}

// Reading `path` must fail with `want`, a message naming the file (and containing `text`, if given), and
// leave the output untouched.
static void expect_read_fails(const char *path, rs_result want, const char *text, const char *what)
{
    rs_image img = { .width = -5 };
    rs_error err = {0};
    rs_result r = rs_image_read_png(path, &img, &err);
    RS_CHECK(r == want, "%s: got %s, want %s (%s)", what, rs_result_name(r), rs_result_name(want), err.msg);
    RS_CHECK(strstr(err.msg, path) != NULL, "%s: message does not name the file: %s", what, err.msg);
    RS_CHECK(!text || strstr(err.msg, text), "%s: message lacks '%s': %s", what, text, err.msg);
    RS_CHECK(img.width == -5 && img.pixels == NULL, "%s: output touched on failure", what);
}

// A small valid PNG written by the module, as raw bytes (for truncation and corruption tests).
static bool valid_png_bytes(uint8_t **data, size_t *len)
{
    rs_image a = {0};
    rs_error err = {0};
    const char *path = tmp_path("valid.png");
    bool ok = make_pattern(16, 12, 3, 0, 255, &a) && rs_image_write_png(path, &a, &err) == RS_OK &&
              read_bytes(path, data, len);
    rs_image_free(&a);
    return ok;
}

static void test_png_read_rejects_truncated_files(void)
{
    uint8_t *data;
    size_t len;
    RS_REQUIRE(valid_png_bytes(&data, &len), "setup");
    const char *path = tmp_path("truncated.png");
    // Every prefix fails cleanly: the signature, inside IHDR, inside IDAT, and just short of IEND.
    for (size_t n = 0; n < len; n++) {
        if (!RS_CHECK(write_bytes(path, data, n), "cannot write %s", path)) break;
        char what[64];
        snprintf(what, sizeof what, "cut at byte %zu of %zu", n, len);
        expect_read_fails(path, RS_ERR_FORMAT, NULL, what);
    }
    free(data);
}

static void test_png_read_survives_every_single_byte_corruption(void)
{
    uint8_t *data;
    size_t len;
    RS_REQUIRE(valid_png_bytes(&data, &len), "setup");
    const char *path = tmp_path("corrupt.png");
    int failed = 0;
    for (size_t i = 0; i < len; i++) {
        data[i] ^= 0x5a;
        bool written = write_bytes(path, data, len);
        data[i] ^= 0x5a;
        if (!RS_CHECK(written, "cannot write %s", path)) break;
        rs_image img = {0};
        rs_error err = {0};
        rs_result r = rs_image_read_png(path, &img, &err);
        RS_CHECK(r == RS_OK || (r == RS_ERR_FORMAT && strstr(err.msg, path)), "byte %zu: %s %s", i,
                 rs_result_name(r), err.msg);
        RS_CHECK(r != RS_OK || (img.width == 16 && img.height == 12 && img.pixels), "byte %zu: bad image", i);
        failed += r != RS_OK;
        rs_image_free(&img);
    }
    // Critical chunks are CRC-checked, so nearly every flip must be caught.
    RS_CHECK(failed > (int)len / 2, "only %d of %zu corruptions detected", failed, len);
    free(data);
}

static void test_png_read_rejects_non_png_directory_and_missing_file(void)
{
    const char *text = tmp_path("not_png.txt");
    RS_REQUIRE(write_bytes(text, "hello, this is not a PNG at all\n", 32), "write");
    expect_read_fails(text, RS_ERR_FORMAT, "not a PNG", "text file");
    const char *empty = tmp_path("empty.png");
    RS_REQUIRE(write_bytes(empty, "", 0), "write");
    expect_read_fails(empty, RS_ERR_FORMAT, "not a PNG", "empty file");
    expect_read_fails(rs_test_out_dir(), RS_ERR_IO, "not a regular file", "directory");
    expect_read_fails(tmp_path("no_such_file.png"), RS_ERR_IO, "cannot open", "missing file");
    expect_read_fails("/dev/zero", RS_ERR_IO, "not a regular file", "device");
}

static void test_png_read_rejects_dimensions_over_limit(void)
{
    uint8_t buf[128];
    size_t n = craft_png(buf, RS_IMAGE_MAX_DIM + 1, 1);
    const char *path = tmp_path("too_wide.png");
    RS_REQUIRE(write_bytes(path, buf, n), "write");
    expect_read_fails(path, RS_ERR_LIMIT, "16385x1", "width over limit");
    n = craft_png(buf, 1, 0x7fffffffu);
    RS_REQUIRE(write_bytes(path, buf, n), "write");
    expect_read_fails(path, RS_ERR_LIMIT, "1x2147483647", "height 2^31-1");
}

static void test_png_read_rejects_header_promising_more_than_file_can_hold(void)
{
    // 16000 x 16000 8-bit grey is 256 MB of pixels; a 70-byte file cannot deflate to that, and the
    // reader must say so before allocating anything.
    uint8_t buf[128];
    size_t n = craft_png(buf, 16000, 16000);
    const char *path = tmp_path("bomb_header.png");
    RS_REQUIRE(write_bytes(path, buf, n), "write");
    expect_read_fails(path, RS_ERR_FORMAT, "cannot hold", "16000x16000 header on a tiny file");
    // The same crafted header with a plausible size decodes far enough to find the data missing.
    n = craft_png(buf, 4, 4);
    RS_REQUIRE(write_bytes(path, buf, n), "write");
    expect_read_fails(path, RS_ERR_FORMAT, NULL, "4x4 header with an empty IDAT");
}

static void test_png_write_to_unwritable_path_fails_and_leaves_no_file(void)
{
    rs_image a = {0};
    RS_REQUIRE(make_pattern(4, 4, 3, 0, 255, &a), "setup");
    const char *paths[] = { tmp_path("no_such_dir/x.png"), "/proc/rouge_test_x.png" };
    for (size_t i = 0; i < RS_COUNT_OF(paths); i++) {
        rs_error err = {0};
        rs_result r = rs_image_write_png(paths[i], &a, &err);
        RS_CHECK(r == RS_ERR_IO, "%s: got %s", paths[i], rs_result_name(r));
        RS_CHECK(strstr(err.msg, paths[i]) != NULL, "message does not name the file: %s", err.msg);
        RS_CHECK(!file_exists(paths[i]), "%s exists after a failed write", paths[i]);
    }
    // Replacing a directory fails at the rename: the directory survives and the temp file is removed.
    const char *dir = tmp_path("a_directory.png");
    RS_REQUIRE(mkdir(dir, 0755) == 0 || errno == EEXIST, "mkdir %s", dir);
    rs_error err = {0};
    RS_CHECK(rs_image_write_png(dir, &a, &err) == RS_ERR_IO, "writing over a directory succeeded");
    struct stat st;
    RS_CHECK(stat(dir, &st) == 0 && S_ISDIR(st.st_mode), "directory damaged");
    char tmp[1100];
    snprintf(tmp, sizeof tmp, "%s.tmp.%ld", dir, (long)getpid());
    RS_CHECK(!file_exists(tmp), "temp file %s left behind", tmp);
    rs_image_free(&a);
}

static void test_png_write_rejects_invalid_image(void)
{
    uint8_t px[12] = { 0 };
    const rs_image bad[] = {
        { .width = 2, .height = 2, .channels = 3, .pixels = NULL },
        { .width = 2, .height = 2, .channels = 2, .pixels = px },
        { .width = 0, .height = 2, .channels = 3, .pixels = px },
    };
    const char *path = tmp_path("invalid.png");
    for (size_t i = 0; i < RS_COUNT_OF(bad); i++) {
        rs_error err = {0};
        RS_CHECK(rs_image_write_png(path, &bad[i], &err) == RS_ERR_ARG, "case %zu accepted", i);
        RS_CHECK(!file_exists(path), "case %zu: file written", i);
    }
}

int main(int argc, char **argv)
{
    rs_test_init(argc, argv);
    RS_RUN(test_create_rejects_bad_sizes_and_channels);
    RS_RUN(test_downsample_averages_light_not_codes);
    RS_RUN(test_identical_images_give_infinite_psnr_and_ssim_exactly_one);
    RS_RUN(test_uniform_offset_gives_exact_psnr_and_abs_errors);
    RS_RUN(test_one_changed_pixel_gives_frac_over_of_one_pixel);
    RS_RUN(test_compare_ignores_alpha);
    RS_RUN(test_compare_and_diff_reject_size_mismatch_naming_both_sizes);
    RS_RUN(test_ciede2000_matches_sharma_published_pairs);
    RS_RUN(test_srgb_to_lab_known_colours);
    RS_RUN(test_delta_e_is_mean_ciede2000_over_pixels);
    RS_RUN(test_ssim_matches_direct_windowed_formula);
    RS_RUN(test_ssim_decreases_with_noise_and_is_symmetric);
    RS_RUN(test_ssim_handles_images_smaller_than_window);
    RS_RUN(test_diff_amplifies_by_four_and_clamps);
    RS_RUN(test_png_round_trip_rgb_is_lossless);
    RS_RUN(test_png_round_trip_rgba_is_lossless);
    RS_RUN(test_png_reads_palette_as_rgb);
    RS_RUN(test_png_reads_4bit_palette_with_transparency_as_rgba);
    RS_RUN(test_png_reads_1bit_grey_as_rgb);
    RS_RUN(test_png_reads_grey_alpha_as_rgba);
    RS_RUN(test_png_reads_16bit_rgb_and_rgba_as_8bit);
    RS_RUN(test_png_reads_interlaced_as_plain_rows);
    RS_RUN(test_png_read_rejects_truncated_files);
    RS_RUN(test_png_read_survives_every_single_byte_corruption);
    RS_RUN(test_png_read_rejects_non_png_directory_and_missing_file);
    RS_RUN(test_png_read_rejects_dimensions_over_limit);
    RS_RUN(test_png_read_rejects_header_promising_more_than_file_can_hold);
    RS_RUN(test_png_write_to_unwritable_path_fails_and_leaves_no_file);
    RS_RUN(test_png_write_rejects_invalid_image);
    return rs_test_finish();
}
