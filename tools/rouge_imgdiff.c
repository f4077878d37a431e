// rouge_imgdiff.c — rouge-imgdiff: compares two PNGs with the metrics image tests use (see src/core/image.h).
//
// Prints one metric per line ("psnr_db 43.21", "ssim 0.987612", ...). Exit status: 0 when compared (and
// within the optional tolerances), 1 when --max-frac or --min-psnr is not met, 2 on bad input or usage,
// with one "rouge-imgdiff: <error>" line on stderr.
#include "core/image.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char usage[] =
    "usage: rouge-imgdiff A.png B.png [--threshold N] [--diff OUT.png] [--max-frac F] [--min-psnr P]\n"
    "\n"
    "Compares two PNGs of the same size (alpha ignored) and prints, one per line:\n"
    "  psnr_db    PSNR over RGB samples in dB (inf when identical)\n"
    "  ssim       mean SSIM of BT.709 luma, 11x11 Gaussian window, sigma 1.5\n"
    "  max_abs    largest per-channel difference, 0..255\n"
    "  mean_abs   mean per-channel absolute difference\n"
    "  delta_e    mean CIEDE2000 colour difference\n"
    "  frac_over  fraction of pixels whose largest channel difference exceeds the threshold\n"
    "\n"
    "  --threshold N   per-pixel threshold for frac_over, 0..255 (default 8)\n"
    "  --diff OUT.png  write |A-B| x4 as a viewable RGB image\n"
    "  --max-frac F    exit 1 when frac_over > F\n"
    "  --min-psnr P    exit 1 when psnr_db < P\n"
    "\n"
    "Exit status: 0 ok, 1 a tolerance not met, 2 bad input or usage.\n";

static int die(const char *msg)
{
    fprintf(stderr, "rouge-imgdiff: %s\n", msg);
    return 2;
}

int main(int argc, char **argv)
{
    const char *paths[2] = { 0 }, *diff_path = NULL;
    int npaths = 0, threshold = 8;
    double max_frac = NAN, min_psnr = NAN;
    char msg[1200];

    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            fputs(usage, stdout);
            return 0;
        }
        bool opt = a[0] == '-' && a[1] == '-';
        if (opt && i + 1 >= argc) {
            snprintf(msg, sizeof msg, "%s needs a value (see --help)", a);
            return die(msg);
        }
        double v;
        if (!strcmp(a, "--threshold")) {
            if (!rs_parse_number(argv[++i], 0, 255, &v) || v != floor(v)) {
                snprintf(msg, sizeof msg, "--threshold '%s': expected an integer 0..255", argv[i]);
                return die(msg);
            }
            threshold = (int)v;
        } else if (!strcmp(a, "--diff")) {
            diff_path = argv[++i];
        } else if (!strcmp(a, "--max-frac")) {
            if (!rs_parse_number(argv[++i], 0, 1, &max_frac)) {
                snprintf(msg, sizeof msg, "--max-frac '%s': expected a number 0..1", argv[i]);
                return die(msg);
            }
        } else if (!strcmp(a, "--min-psnr")) {
            if (!rs_parse_number(argv[++i], -HUGE_VAL, HUGE_VAL, &min_psnr)) {
                snprintf(msg, sizeof msg, "--min-psnr '%s': expected a number of dB", argv[i]);
                return die(msg);
            }
        } else if (opt) {
            snprintf(msg, sizeof msg, "unknown option '%s' (see --help)", a);
            return die(msg);
        } else if (npaths < 2) {
            paths[npaths++] = a;
        } else {
            snprintf(msg, sizeof msg, "unexpected argument '%s': give exactly two PNGs (see --help)", a);
            return die(msg);
        }
    }
    if (npaths != 2) return die("give two PNG files to compare (see --help)");

    rs_error err = {0};
    rs_image img[2] = { { 0 }, { 0 } };
    rs_image_metrics m;
    int status = 0;
    if (rs_image_read_png(paths[0], &img[0], &err) != RS_OK || rs_image_read_png(paths[1], &img[1], &err) != RS_OK) {
        status = die(err.msg);
    } else if (rs_image_compare(&img[0], &img[1], threshold, &m, &err) != RS_OK) {
        snprintf(msg, sizeof msg, "%s vs %s: %s", paths[0], paths[1], err.msg);
        status = die(msg);
    } else if (diff_path) {
        rs_image d = {0};
        if (rs_image_diff(&img[0], &img[1], &d, &err) != RS_OK || rs_image_write_png(diff_path, &d, &err) != RS_OK)
            status = die(err.msg);
        rs_image_free(&d);
    }
    rs_image_free(&img[0]);
    rs_image_free(&img[1]);
    if (status) return status;

    if (isinf(m.psnr)) printf("psnr_db inf\n");
    else printf("psnr_db %.2f\n", m.psnr);
    printf("ssim %.6f\n", m.ssim);
    printf("max_abs %d\n", m.max_abs);
    printf("mean_abs %.4f\n", m.mean_abs);
    printf("delta_e %.4f\n", m.delta_e);
    printf("frac_over %.6f (threshold %d)\n", m.frac_over, threshold);

    if (!isnan(max_frac) && m.frac_over > max_frac) {
        fprintf(stderr, "rouge-imgdiff: frac_over %.6f exceeds --max-frac %g\n", m.frac_over, max_frac);
        status = 1;
    }
    if (!isnan(min_psnr) && m.psnr < min_psnr) {
        fprintf(stderr, "rouge-imgdiff: psnr_db %.2f below --min-psnr %g\n", m.psnr, min_psnr);
        status = 1;
    }
    return status;
}
