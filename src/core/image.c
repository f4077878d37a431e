// image.c — see image.h.
//
// PNG decoding works on an in-memory copy of the file (rs_file_read_all refuses directories, devices and
// huge files), so libpng never touches a FILE*. libpng reports errors by longjmp; every function that
// calls setjmp keeps its mutable state in a struct reached through a pointer, so nothing it needs after
// the jump lives in a local variable the jump may have clobbered (C11 7.13.2.1p3).
#include "core/image.h"

#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// A PNG bigger than this is not a test image; the cap keeps a hostile path from filling memory.
#define PNG_MAX_FILE_BYTES ((size_t)1 << 30)

// Deflate cannot expand input by more than 1032:1 (a 258-byte match per 2 bits, RFC 1951), so a file
// of n bytes cannot decode to more than about 1032 n bytes of filtered scanlines. Checking the header's
// claim against it before allocating stops a 100-byte file from asking for a 1 GiB pixel buffer.
#define DEFLATE_MAX_RATIO 1032u

rs_result rs_image_create(int width, int height, int channels, rs_image *out, rs_error *err)
{
    if (width < 1 || height < 1 || width > RS_IMAGE_MAX_DIM || height > RS_IMAGE_MAX_DIM)
        return rs_fail(err, RS_ERR_ARG, "image size %dx%d outside 1..%d", width, height, RS_IMAGE_MAX_DIM);
    if (channels != 3 && channels != 4)
        return rs_fail(err, RS_ERR_ARG, "image channels %d: must be 3 (RGB) or 4 (RGBA)", channels);
    size_t n;
    if (!rs_size_mul((size_t)width, (size_t)height, &n) || !rs_size_mul(n, (size_t)channels, &n))
        return rs_fail(err, RS_ERR_LIMIT, "image size %dx%dx%d overflows", width, height, channels);
    uint8_t *px = calloc(n, 1);
    if (!px) return rs_fail(err, RS_ERR_NOMEM, "out of memory for a %dx%d image", width, height);
    *out = (rs_image){ .width = width, .height = height, .channels = channels, .pixels = px };
    return RS_OK;
}

rs_result rs_image_downsample(const rs_image *in, int factor, rs_image *out, rs_error *err)
{
    if (factor < 1 || !in->pixels || in->width % factor || in->height % factor)
        return rs_fail(err, RS_ERR_ARG, "downsample: %dx%d is not a multiple of %d", in->width, in->height, factor);
    rs_result r = rs_image_create(in->width / factor, in->height / factor, in->channels, out, err);
    if (r) return r;
    float lin[256];
    for (int i = 0; i < 256; i++) lin[i] = rs_srgb_to_linear((float)i / 255.0f);
    int ch = in->channels;
    float inv = 1.0f / (float)(factor * factor);
    for (int y = 0; y < out->height; y++)
        for (int x = 0; x < out->width; x++) {
            float sum[4] = {0};
            for (int dy = 0; dy < factor; dy++) {
                const uint8_t *p = in->pixels + (((size_t)y * factor + dy) * in->width + (size_t)x * factor) * ch;
                for (int dx = 0; dx < factor; dx++, p += ch)
                    for (int c = 0; c < ch; c++) sum[c] += c < 3 ? lin[p[c]] : (float)p[c];
            }
            uint8_t *o = out->pixels + ((size_t)y * out->width + x) * ch;
            for (int c = 0; c < ch; c++)
                o[c] = (uint8_t)lrintf(c < 3 ? 255.0f * rs_linear_to_srgb(sum[c] * inv) : sum[c] * inv);
        }
    return RS_OK;
}

void rs_image_free(rs_image *img)
{
    if (!img) return;
    free(img->pixels);
    *img = (rs_image){0};
}

static bool image_valid(const rs_image *img)
{
    return img && img->pixels && img->width >= 1 && img->height >= 1 && img->width <= RS_IMAGE_MAX_DIM &&
           img->height <= RS_IMAGE_MAX_DIM && (img->channels == 3 || img->channels == 4);
}

// ---------------------------------------------------------------------------------------------------
// PNG reading

typedef struct png_reader {
    const uint8_t *data;
    size_t len, pos;
    png_structp png;
    png_infop info;
    rs_result code;     // the failure class when decode() returns false
    char msg[256];      // libpng's or our own message for the failure
    uint8_t *pixels;    // owned until handed to the caller
    png_bytep *rows;
    int width, height, channels;
} png_reader;

static void png_on_error(png_structp png, png_const_charp msg)
{
    png_reader *r = png_get_error_ptr(png);
    snprintf(r->msg, sizeof r->msg, "%s", msg);
    png_longjmp(png, 1);
}

// Library modules never print; libpng's warnings (bad ancillary chunks and the like) are dropped.
static void png_on_warning(png_structp png, png_const_charp msg)
{
    (void)png;
    (void)msg;
}

static void png_read_mem(png_structp png, png_bytep dst, png_size_t n)
{
    png_reader *r = png_get_io_ptr(png);
    if (n > r->len - r->pos) {
        snprintf(r->msg, sizeof r->msg, "file is truncated (needed %zu bytes at byte %zu, %zu left)", (size_t)n,
                 r->pos, r->len - r->pos);
        png_longjmp(png, 1);
    }
    memcpy(dst, r->data + r->pos, n);
    r->pos += n;
}

// Fails from inside decode() with our own code and message (libpng's failures stay RS_ERR_FORMAT).
static bool reader_fail(png_reader *r, rs_result code, const char *what)
{
    r->code = code;
    snprintf(r->msg, sizeof r->msg, "%s", what);
    return false;
}

// Decodes r->data into r->pixels. All state lives in *r so it survives libpng's longjmp.
static bool decode(png_reader *r)
{
    if (setjmp(png_jmpbuf(r->png))) return false;
    png_set_read_fn(r->png, r, png_read_mem);
    // Our own limit (below) gives a clearer error than libpng's default 1e6 user limit would.
    png_set_user_limits(r->png, 0x7fffffffu, 0x7fffffffu);
    png_read_info(r->png, r->info);

    png_uint_32 w, h;
    int depth, color, interlace;
    png_get_IHDR(r->png, r->info, &w, &h, &depth, &color, &interlace, NULL, NULL);
    if (w > RS_IMAGE_MAX_DIM || h > RS_IMAGE_MAX_DIM) {
        char m[128];
        snprintf(m, sizeof m, "image is %ux%u, larger than the %d allowed", (unsigned)w, (unsigned)h,
                 RS_IMAGE_MAX_DIM);
        return reader_fail(r, RS_ERR_LIMIT, m);
    }
    int in_channels = png_get_channels(r->png, r->info);
    // Lower bound of the decompressed image data the header promises (filter bytes not counted).
    uint64_t min_raw = ((uint64_t)w * (uint64_t)h * (uint64_t)(depth * in_channels) + 7) / 8;
    if (min_raw > (uint64_t)DEFLATE_MAX_RATIO * r->len + 4096) {
        char m[160];
        snprintf(m, sizeof m, "header claims %ux%u pixels but the %zu-byte file cannot hold that much data",
                 (unsigned)w, (unsigned)h, r->len);
        return reader_fail(r, RS_ERR_FORMAT, m);
    }

    bool alpha = (color & PNG_COLOR_MASK_ALPHA) || png_get_valid(r->png, r->info, PNG_INFO_tRNS);
    // Palette -> RGB, grey < 8 bit -> 8 bit, tRNS -> alpha channel.
    png_set_expand(r->png);
#ifdef PNG_READ_SCALE_16_TO_8_SUPPORTED
    png_set_scale_16(r->png);  // rounds (v * 255 / 65535) rather than dropping the low byte
#else
    png_set_strip_16(r->png);
#endif
    if (!(color & PNG_COLOR_MASK_COLOR)) png_set_gray_to_rgb(r->png);
    png_set_interlace_handling(r->png);
    png_read_update_info(r->png, r->info);

    r->channels = alpha ? 4 : 3;
    size_t row_bytes = (size_t)w * (size_t)r->channels;
    if (png_get_channels(r->png, r->info) != r->channels || png_get_bit_depth(r->png, r->info) != 8 ||
        png_get_rowbytes(r->png, r->info) != row_bytes)
        return reader_fail(r, RS_ERR_FORMAT, "unsupported PNG layout after conversion to 8-bit RGB(A)");

    r->width = (int)w;
    r->height = (int)h;
    r->pixels = rs_alloc_array(row_bytes, h);
    r->rows = rs_alloc_array(h, sizeof *r->rows);
    if (!r->pixels || !r->rows) return reader_fail(r, RS_ERR_NOMEM, "out of memory for the pixels");
    for (png_uint_32 y = 0; y < h; y++) r->rows[y] = r->pixels + (size_t)y * row_bytes;
    png_read_image(r->png, r->rows);
    // Reads up to IEND so a file cut after its image data is still reported as truncated.
    png_read_end(r->png, NULL);
    return true;
}

rs_result rs_image_read_png_memory(const void *data, size_t len, const char *name, rs_image *out, rs_error *err)
{
    if (len < 8 || png_sig_cmp(data, 0, 8) != 0)
        return rs_fail(err, RS_ERR_FORMAT, "%s: not a PNG file (bad signature at byte 0)", name);
    rs_result res = RS_OK;
    png_reader r = { .data = data, .len = len, .code = RS_ERR_FORMAT };
    r.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &r, png_on_error, png_on_warning);
    r.info = r.png ? png_create_info_struct(r.png) : NULL;
    if (!r.png || !r.info) {
        res = rs_fail(err, RS_ERR_NOMEM, "%s: out of memory for the PNG decoder", name);
    } else if (!decode(&r)) {
        res = rs_fail(err, r.code, "%s: %s", name, r.msg);
    } else {
        *out = (rs_image){ .width = r.width, .height = r.height, .channels = r.channels, .pixels = r.pixels };
        r.pixels = NULL;
    }
    png_destroy_read_struct(&r.png, &r.info, NULL);
    free(r.rows);
    free(r.pixels);
    return res;
}

rs_result rs_image_read_png(const char *path, rs_image *out, rs_error *err)
{
    void *data;
    size_t len;
    rs_result res = rs_file_read_all(path, PNG_MAX_FILE_BYTES, &data, &len, err);
    if (res != RS_OK) return res;
    res = rs_image_read_png_memory(data, len, path, out, err);
    free(data);
    return res;
}

// ---------------------------------------------------------------------------------------------------
// PNG writing

typedef struct png_writer {
    const rs_image *img;
    png_structp png;
    png_infop info;
    uint8_t *buf;
    size_t len, cap;
    png_bytep *rows;
    bool nomem;
    char msg[256];
} png_writer;

static void png_write_mem(png_structp png, png_bytep src, png_size_t n)
{
    png_writer *w = png_get_io_ptr(png);
    if (n > w->cap - w->len) {
        size_t need, cap = w->cap ? w->cap : 4096;
        if (!rs_size_add(w->len, n, &need)) png_error(png, "PNG larger than memory");
        while (cap < need) cap = cap > SIZE_MAX / 2 ? need : cap * 2;
        uint8_t *p = realloc(w->buf, cap);
        if (!p) {
            w->nomem = true;
            png_error(png, "out of memory for the encoded PNG");
        }
        w->buf = p;
        w->cap = cap;
    }
    memcpy(w->buf + w->len, src, n);
    w->len += n;
}

static void png_flush_mem(png_structp png)
{
    (void)png;
}

static void png_on_write_error(png_structp png, png_const_charp msg)
{
    png_writer *w = png_get_error_ptr(png);
    snprintf(w->msg, sizeof w->msg, "%s", msg);
    png_longjmp(png, 1);
}

// Encodes w->img into w->buf. All state lives in *w so it survives libpng's longjmp.
static bool encode(png_writer *w)
{
    if (setjmp(png_jmpbuf(w->png))) return false;
    const rs_image *img = w->img;
    size_t row_bytes = (size_t)img->width * (size_t)img->channels;
    w->rows = rs_alloc_array((size_t)img->height, sizeof *w->rows);
    if (!w->rows) {
        w->nomem = true;
        snprintf(w->msg, sizeof w->msg, "out of memory for row pointers");
        return false;
    }
    for (int y = 0; y < img->height; y++) w->rows[y] = img->pixels + (size_t)y * row_bytes;
    png_set_write_fn(w->png, w, png_write_mem, png_flush_mem);
    png_set_IHDR(w->png, w->info, (png_uint_32)img->width, (png_uint_32)img->height, 8,
                 img->channels == 4 ? PNG_COLOR_TYPE_RGB_ALPHA : PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB(w->png, w->info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_write_info(w->png, w->info);
    png_write_image(w->png, w->rows);
    png_write_end(w->png, NULL);
    return true;
}

rs_result rs_image_write_png(const char *path, const rs_image *img, rs_error *err)
{
    if (!image_valid(img))
        return rs_fail(err, RS_ERR_ARG, "%s: cannot write an invalid image (%dx%d, %d channels%s)", path,
                       img ? img->width : 0, img ? img->height : 0, img ? img->channels : 0,
                       img && !img->pixels ? ", no pixels" : "");
    png_writer w = { .img = img };
    rs_result res = RS_OK;
    w.png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &w, png_on_write_error, png_on_warning);
    w.info = w.png ? png_create_info_struct(w.png) : NULL;
    if (!w.png || !w.info)
        res = rs_fail(err, RS_ERR_NOMEM, "%s: out of memory for the PNG encoder", path);
    else if (!encode(&w))
        res = rs_fail(err, w.nomem ? RS_ERR_NOMEM : RS_ERR_FORMAT, "%s: PNG encoding failed: %s", path, w.msg);
    png_destroy_write_struct(&w.png, &w.info);
    if (res == RS_OK) res = rs_file_write_atomic(path, w.buf, w.len, err);
    free(w.rows);
    free(w.buf);
    return res;
}

// ---------------------------------------------------------------------------------------------------
// Colour: sRGB -> CIELAB and CIEDE2000

static double srgb8_to_linear(uint8_t v) { return rs_srgb_to_linear(v / 255.0f); }

static double lab_f(double t)
{
    // CIE 15: cube root above (6/29)^3, the linear segment below.
    const double d = 6.0 / 29.0;
    return t > d * d * d ? cbrt(t) : t / (3.0 * d * d) + 4.0 / 29.0;
}

// Linear sRGB -> XYZ (D65, IEC 61966-2-1 primaries) -> CIELAB relative to the D65 white the matrix maps
// RGB (1,1,1) to, so sRGB white lands exactly on a* = b* = 0.
static void linear_to_lab(const double rgb[3], double lab[3])
{
    const double m[3][3] = {
        { 0.4124564, 0.3575761, 0.1804375 },
        { 0.2126729, 0.7151522, 0.0721750 },
        { 0.0193339, 0.1191920, 0.9503041 },
    };
    double f[3];
    for (int i = 0; i < 3; i++) {
        double white = m[i][0] + m[i][1] + m[i][2];
        f[i] = lab_f((m[i][0] * rgb[0] + m[i][1] * rgb[1] + m[i][2] * rgb[2]) / white);
    }
    lab[0] = 116.0 * f[1] - 16.0;
    lab[1] = 500.0 * (f[0] - f[1]);
    lab[2] = 200.0 * (f[1] - f[2]);
}

void rs_srgb8_to_lab(const uint8_t rgb[3], double lab[3])
{
    double lin[3] = { srgb8_to_linear(rgb[0]), srgb8_to_linear(rgb[1]), srgb8_to_linear(rgb[2]) };
    linear_to_lab(lin, lab);
}

#define PI 3.14159265358979323846

static double deg(double r)
{
    return r * (180.0 / PI);
}

static double rad(double d)
{
    return d * (PI / 180.0);
}

// Lab chromas are far from overflow, so the plain formula replaces the (much slower) hypot().
static double chroma(double a, double b)
{
    return sqrt(a * a + b * b);
}

static double pow7(double x)
{
    double x2 = x * x;
    return x2 * x2 * x2 * x;
}

// CIEDE2000 with kL = kC = kH = 1, following Sharma, Wu & Dalal (2005) eqs. (1)-(22); the numbered
// comments are theirs. Hue angles in degrees as in the paper.
double rs_ciede2000(const double lab1[3], const double lab2[3])
{
    double L1 = lab1[0], a1 = lab1[1], b1 = lab1[2];
    double L2 = lab2[0], a2 = lab2[1], b2 = lab2[2];
    // (2)-(3): mean chroma and the a* stretch G
    double Cab = 0.5 * (chroma(a1, b1) + chroma(a2, b2));
    double Cab7 = pow7(Cab);
    double G = 0.5 * (1.0 - sqrt(Cab7 / (Cab7 + 6103515625.0)));  // 25^7
    // (4)-(7): a', C', h' (h' = 0 where a' = b' = 0)
    double a1p = (1.0 + G) * a1, a2p = (1.0 + G) * a2;
    double C1p = chroma(a1p, b1), C2p = chroma(a2p, b2);
    double h1p = (a1p == 0.0 && b1 == 0.0) ? 0.0 : deg(atan2(b1, a1p));
    double h2p = (a2p == 0.0 && b2 == 0.0) ? 0.0 : deg(atan2(b2, a2p));
    if (h1p < 0.0) h1p += 360.0;
    if (h2p < 0.0) h2p += 360.0;
    // (8)-(10): differences; dh' = 0 when either chroma is zero
    double dLp = L2 - L1, dCp = C2p - C1p;
    double dhp = 0.0;
    if (C1p * C2p != 0.0) {
        dhp = h2p - h1p;
        if (dhp > 180.0) dhp -= 360.0;
        else if (dhp < -180.0) dhp += 360.0;
    }
    double dHp = 2.0 * sqrt(C1p * C2p) * sin(rad(dhp) / 2.0);
    // (12)-(14): means; the hue mean takes the short way round the circle
    double Lbp = 0.5 * (L1 + L2), Cbp = 0.5 * (C1p + C2p);
    double hbp = h1p + h2p;
    if (C1p * C2p != 0.0) {
        if (fabs(h1p - h2p) <= 180.0) hbp *= 0.5;
        else if (h1p + h2p < 360.0) hbp = 0.5 * (hbp + 360.0);
        else hbp = 0.5 * (hbp - 360.0);
    }
    // (15)-(21): weighting functions and the rotation term
    double T = 1.0 - 0.17 * cos(rad(hbp - 30.0)) + 0.24 * cos(rad(2.0 * hbp)) + 0.32 * cos(rad(3.0 * hbp + 6.0)) -
               0.20 * cos(rad(4.0 * hbp - 63.0));
    double dtheta = 30.0 * exp(-((hbp - 275.0) / 25.0) * ((hbp - 275.0) / 25.0));
    double Cbp7 = pow7(Cbp);
    double RC = 2.0 * sqrt(Cbp7 / (Cbp7 + 6103515625.0));
    double Lm = (Lbp - 50.0) * (Lbp - 50.0);
    double SL = 1.0 + 0.015 * Lm / sqrt(20.0 + Lm);
    double SC = 1.0 + 0.045 * Cbp;
    double SH = 1.0 + 0.015 * Cbp * T;
    double RT = -sin(rad(2.0 * dtheta)) * RC;
    // (22)
    double tL = dLp / SL, tC = dCp / SC, tH = dHp / SH;
    return sqrt(tL * tL + tC * tC + tH * tH + RT * tC * tH);
}

// ---------------------------------------------------------------------------------------------------
// Metrics

static rs_result check_pair(const rs_image *a, const rs_image *b, rs_error *err)
{
    if (!image_valid(a) || !image_valid(b))
        return rs_fail(err, RS_ERR_ARG, "invalid image (no pixels, or a bad size or channel count)");
    if (a->width != b->width || a->height != b->height)
        return rs_fail(err, RS_ERR_ARG, "image sizes differ: %dx%d vs %dx%d", a->width, a->height, b->width,
                       b->height);
    return RS_OK;
}

// Normalised 1-D Gaussian taps (sigma 1.5) for a window of k <= 11 samples centred on the window.
static void gauss_taps(int k, double taps[11])
{
    double sum = 0.0, c = 0.5 * (k - 1);
    for (int i = 0; i < k; i++) {
        double d = i - c;
        taps[i] = exp(-d * d / (2.0 * 1.5 * 1.5));
        sum += taps[i];
    }
    for (int i = 0; i < k; i++) taps[i] /= sum;
}

// Window width along an axis of n pixels: 11, or the largest odd width that fits a smaller image.
static int window_size(int n)
{
    int k = RS_MIN(11, n);
    return k % 2 ? k : k - 1;
}

// Luma of an 8-bit sRGB-encoded pixel with BT.709 / sRGB weights (on the encoded values, as SSIM
// implementations do; not linear luminance).
static double luma(const uint8_t *p)
{
    return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
}

// Horizontal pass for one image row: the five moments x, y, x^2, y^2, xy of the two luma rows, each
// Gaussian-weighted over kx samples, at every valid column. `m` holds five runs of ow values.
static void ssim_row_moments(const double *ya, const double *yb, int ow, int kx, const double *tx, double *m)
{
    for (int x = 0; x < ow; x++) {
        double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
        for (int i = 0; i < kx; i++) {
            double u = ya[x + i], v = yb[x + i], t = tx[i];
            sx += t * u;
            sy += t * v;
            sxx += t * (u * u);
            syy += t * (v * v);
            sxy += t * (u * v);  // grouped like the squares: symmetric, and exact when a == b
        }
        m[x] = sx;
        m[ow + x] = sy;
        m[2 * ow + x] = sxx;
        m[3 * ow + x] = syy;
        m[4 * ow + x] = sxy;
    }
}

// Mean SSIM (Wang, Bovik, Sheikh & Simoncelli 2004, eq. 13) over every position where the Gaussian
// window fits inside the image ("valid" positions, as in the authors' ssim.m). The five local moments
// are Gaussian-weighted sums; the 2-D Gaussian is separable, so each is a horizontal then a vertical
// 1-D pass: O(k) per pixel instead of O(k^2). Horizontal results live in a ring of ky rows, so memory
// stays O(width) for any image height.
static rs_result ssim_luma(const rs_image *a, const rs_image *b, double *out, rs_error *err)
{
    int w = a->width, h = a->height;
    int kx = window_size(w), ky = window_size(h);
    int ow = w - kx + 1, oh = h - ky + 1;
    double tx[11], ty[11];
    gauss_taps(kx, tx);
    gauss_taps(ky, ty);

    size_t ring = (size_t)ky * 5 * (size_t)ow;
    double *buf = rs_alloc_array(ring + 2 * (size_t)w, sizeof(double));
    if (!buf) return rs_fail(err, RS_ERR_NOMEM, "ssim: out of memory for a %d-pixel-wide image", w);
    double *ya = buf + ring, *yb = ya + w;

    // Constants of eq. (13) with K1 = 0.01, K2 = 0.03, L = 255.
    const double C1 = (0.01 * 255) * (0.01 * 255), C2 = (0.03 * 255) * (0.03 * 255);
    double sum = 0.0;
    for (int r = 0; r < h; r++) {
        const uint8_t *pa = a->pixels + (size_t)r * w * a->channels;
        const uint8_t *pb = b->pixels + (size_t)r * w * b->channels;
        for (int x = 0; x < w; x++) {
            ya[x] = luma(pa + (size_t)x * a->channels);
            yb[x] = luma(pb + (size_t)x * b->channels);
        }
        ssim_row_moments(ya, yb, ow, kx, tx, buf + (size_t)(r % ky) * 5 * ow);
        if (r < ky - 1) continue;
        // Rows r-ky+1 .. r are in the ring: the vertical pass for output row r-ky+1.
        int y0 = r - ky + 1;
        for (int x = 0; x < ow; x++) {
            double ux = 0, uy = 0, exx = 0, eyy = 0, exy = 0;
            for (int j = 0; j < ky; j++) {
                const double *m = buf + (size_t)((y0 + j) % ky) * 5 * ow + x;
                double t = ty[j];
                ux += t * m[0];
                uy += t * m[ow];
                exx += t * m[2 * ow];
                eyy += t * m[3 * ow];
                exy += t * m[4 * ow];
            }
            // Parenthesised so that swapping a and b only swaps the operands of single (commutative)
            // operations: SSIM(a,b) == SSIM(b,a) bit for bit, and identical inputs give exactly 1.
            double vx = exx - ux * ux, vy = eyy - uy * uy, cxy = exy - ux * uy;
            sum += ((2.0 * (ux * uy) + C1) * (2.0 * cxy + C2)) / ((ux * ux + uy * uy + C1) * (vx + vy + C2));
        }
    }
    free(buf);
    *out = sum / ((double)ow * (double)oh);
    return RS_OK;
}

rs_result rs_image_compare(const rs_image *a, const rs_image *b, int threshold, rs_image_metrics *out,
                           rs_error *err)
{
    rs_result res = check_pair(a, b, err);
    if (res != RS_OK) return res;
    double ssim = 0.0;
    res = ssim_luma(a, b, &ssim, err);
    if (res != RS_OK) return res;

    double lin[256];
    for (int i = 0; i < 256; i++) lin[i] = srgb8_to_linear((uint8_t)i);

    size_t npx = (size_t)a->width * (size_t)a->height;
    uint64_t sse = 0, sad = 0, over = 0;
    int max_abs = 0;
    double de_sum = 0.0;
    for (size_t i = 0; i < npx; i++) {
        const uint8_t *pa = a->pixels + i * a->channels, *pb = b->pixels + i * b->channels;
        int pmax = 0;
        for (int c = 0; c < 3; c++) {
            int d = abs((int)pa[c] - (int)pb[c]);
            sse += (uint64_t)(d * d);
            sad += (uint64_t)d;
            pmax = RS_MAX(pmax, d);
        }
        max_abs = RS_MAX(max_abs, pmax);
        if (pmax > threshold) over++;
        // Equal colours have delta E 0; skipping them keeps the common near-identical case cheap.
        if (pmax > 0) {
            double la[3], lb[3];
            double ra[3] = { lin[pa[0]], lin[pa[1]], lin[pa[2]] }, rb[3] = { lin[pb[0]], lin[pb[1]], lin[pb[2]] };
            linear_to_lab(ra, la);
            linear_to_lab(rb, lb);
            de_sum += rs_ciede2000(la, lb);
        }
    }
    double nsamples = 3.0 * (double)npx;
    // PSNR = 10 log10(L^2 / MSE), L = 255, over all RGB samples.
    double mse = (double)sse / nsamples;
    *out = (rs_image_metrics){
        .psnr = sse == 0 ? INFINITY : 10.0 * log10(255.0 * 255.0 / mse),
        .ssim = ssim,
        .max_abs = max_abs,
        .mean_abs = (double)sad / nsamples,
        .delta_e = de_sum / (double)npx,
        .frac_over = (double)over / (double)npx,
    };
    return RS_OK;
}

rs_result rs_image_diff(const rs_image *a, const rs_image *b, rs_image *out, rs_error *err)
{
    rs_result res = check_pair(a, b, err);
    if (res != RS_OK) return res;
    rs_image d;
    res = rs_image_create(a->width, a->height, 3, &d, err);
    if (res != RS_OK) return res;
    size_t npx = (size_t)a->width * (size_t)a->height;
    for (size_t i = 0; i < npx; i++) {
        const uint8_t *pa = a->pixels + i * a->channels, *pb = b->pixels + i * b->channels;
        for (int c = 0; c < 3; c++) d.pixels[i * 3 + c] = (uint8_t)RS_MIN(255, 4 * abs((int)pa[c] - (int)pb[c]));
    }
    *out = d;
    return RS_OK;
}
