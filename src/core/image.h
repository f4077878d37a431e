// image.h — 8-bit RGB/RGBA images: PNG read/write (libpng) and the metrics image tests compare with.
//
// Does: read any PNG into 8-bit RGB or RGBA (palette, grey, 16-bit and interlaced are converted);
// write 8-bit PNGs atomically (temp + rename); compare two images: PSNR, SSIM (Gaussian-windowed, on
// luminance), max / mean absolute difference, mean CIEDE2000 delta E, and the fraction of pixels whose
// largest channel difference exceeds a threshold (the two-number tolerance); a visual diff image.
// Does not: colour-manage, resample, or read anything but PNG.
//
//   rs_image a = {0}, b = {0};
//   rs_image_metrics m;
//   if (rs_image_read_png("a.png", &a, &err) == RS_OK && rs_image_read_png("b.png", &b, &err) == RS_OK &&
//       rs_image_compare(&a, &b, 8, &m, &err) == RS_OK)
//       printf("PSNR %.2f dB, SSIM %.4f\n", m.psnr, m.ssim);
//   rs_image_free(&a); rs_image_free(&b);
#ifndef RS_IMAGE_H
#define RS_IMAGE_H

#include "core/core.h"

#define RS_IMAGE_MAX_DIM 16384

// Rows top-first, tightly packed, channels interleaved (3 = RGB, 4 = RGBA), sRGB-encoded.
typedef struct rs_image {
    int width, height, channels;
    uint8_t *pixels;
} rs_image;

typedef struct rs_image_metrics {
    double psnr;        // dB over RGB samples; INFINITY when identical
    double ssim;        // mean SSIM of BT.709 luma of the sRGB values, 11x11 Gaussian window (sigma 1.5;
                        // smaller images use the largest odd window that fits), 1.0 when identical
    int max_abs;        // largest per-channel difference (RGB), 0..255
    double mean_abs;    // mean per-channel absolute difference (RGB)
    double delta_e;     // mean CIEDE2000 over pixels (sRGB D65 -> Lab)
    double frac_over;   // fraction of pixels whose largest RGB difference exceeds `threshold`
} rs_image_metrics;

// Allocates a zeroed image; channels must be 3 or 4.
rs_result rs_image_create(int width, int height, int channels, rs_image *out, rs_error *err);
void rs_image_free(rs_image *img);

rs_result rs_image_read_png(const char *path, rs_image *out, rs_error *err);
// The same from a PNG file's bytes (e.g. embedded in a GLB); `name` prefixes the messages.
rs_result rs_image_read_png_memory(const void *data, size_t len, const char *name, rs_image *out, rs_error *err);
rs_result rs_image_write_png(const char *path, const rs_image *img, rs_error *err);

// in reduced by a whole factor in each direction (its size must be a multiple of it): each out pixel the
// mean of a factor x factor block, in linear light (sRGB decoded, averaged, encoded; alpha averaged as is).
// Supersampled renders use it, so an edge's pixel shows the share of each side a camera would.
rs_result rs_image_downsample(const rs_image *in, int factor, rs_image *out, rs_error *err);

// a and b must have the same size; alpha is ignored. `threshold` feeds frac_over.
rs_result rs_image_compare(const rs_image *a, const rs_image *b, int threshold, rs_image_metrics *out,
                           rs_error *err);
// A viewable RGB diff: |a-b| per channel amplified x4, for test failure artefacts.
rs_result rs_image_diff(const rs_image *a, const rs_image *b, rs_image *out, rs_error *err);

// CIEDE2000 between two CIELAB colours (exposed for the published-test-data unit test).
double rs_ciede2000(const double lab1[3], const double lab2[3]);
// sRGB 8-bit -> CIELAB (D65).
void rs_srgb8_to_lab(const uint8_t rgb[3], double lab[3]);

#endif
