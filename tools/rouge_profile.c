// rouge_profile.c — rouge-profile: fits K Gaussians to the six-Gaussian skin profile, prints the fit and its error.
//
// This is where the README's and the bench's kernel numbers come from (src/render/profile.h does the work; the renderer
// runs the same fit at start-up). Exit status: 0 done, 2 bad usage, with one "rouge-profile: <error>" line.
#include "render/profile.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char usage[] =
    "usage: rouge-profile [--k K] [--footprint MM] [--objective edge|radial|both]\n"
    "\n"
    "Fits K Gaussians (variances shared by R, G, B; weights >= 0 summing to 1 per channel) to d'Eon & Luebke's\n"
    "six-Gaussian skin profile, both pre-blurred by a pixel footprint Gaussian of sigma MM, and prints for each fit:\n"
    "  variance_mm2      the K variances, narrow to wide\n"
    "  weight_r/g/b      the per-channel weights\n"
    "  edge_err_pct      worst |ESF_fit - ESF_6| over x in [-10, 10] mm, % of the lit level (1/255 = 0.39%),\n"
    "                    R G B and max, at the fit's footprint and at footprints 0, 0.05, 0.1, 0.2 mm\n"
    "  radial_rel_l2     ||R_fit - R_6|| / ||R_6|| over the plane, R G B\n"
    "  fit_ms            time of one fit (best of 5), iterations of Nelder-Mead\n"
    "\n"
    "  --k K          2..5 (default: 2, 3 and 4)\n"
    "  --footprint MM pixel footprint sigma in mm, 0..10 (default 0.05)\n"
    "  --objective    edge: least squares on the edge response (the renderer's default);\n"
    "                 radial: least squares on R(r) over the plane; both (default)\n";

static int die(const char *msg)
{
    fprintf(stderr, "rouge-profile: %s\n", msg);
    return 2;
}

static void print_row(const char *name, const rs_profile *p, int channel)
{
    printf("  %-14s", name);
    for (int i = 0; i < p->count; i++)
        printf(" %9.4f", channel < 0 ? p->variance_mm2[i] : p->weight[i][channel]);
    printf("\n");
}

static int fit_and_print(int k, double footprint_mm, rs_profile_objective objective)
{
    rs_profile fit;
    rs_profile_fit_report rep;
    rs_error err = { 0 };
    double best_ms = INFINITY;
    for (int run = 0; run < 5; run++) {
        double t0 = rs_time_now();
        if (rs_profile_fit_objective(k, footprint_mm, objective, &fit, &rep, &err) != RS_OK) return die(err.msg);
        best_ms = fmin(best_ms, (rs_time_now() - t0) * 1e3);
    }
    const char *name = objective == RS_PROFILE_FIT_EDGE ? "edge" : "radial";
    printf("K=%d objective %s footprint %.3f mm\n", k, name, footprint_mm);
    print_row("variance_mm2", &fit, -1);
    print_row("weight_r", &fit, 0);
    print_row("weight_g", &fit, 1);
    print_row("weight_b", &fit, 2);
    const double *e = rep.max_edge_error_channel;
    printf("  %-14s %.3f %.3f %.3f max %.3f (footprint %.3f mm)\n", "edge_err_pct", 100 * e[0], 100 * e[1],
           100 * e[2], 100 * rep.max_edge_error, footprint_mm);
    rs_profile deon = rs_profile_deon();
    static const double other[] = { 0.0, 0.05, 0.1, 0.2 };
    for (size_t i = 0; i < RS_COUNT_OF(other); i++) {
        double pc[3], m = rs_profile_max_edge_error(&fit, &deon, other[i], pc);
        printf("  %-14s %.3f %.3f %.3f max %.3f (footprint %.3f mm)\n", "", 100 * pc[0], 100 * pc[1], 100 * pc[2],
               100 * m, other[i]);
    }
    printf("  %-14s %.4f %.4f %.4f\n", "radial_rel_l2", rep.rms_radial[0], rep.rms_radial[1], rep.rms_radial[2]);
    printf("  %-14s %.2f iterations %d\n", "fit_ms", best_ms, rep.iterations);
    return 0;
}

int main(int argc, char **argv)
{
    int k = 0;
    double footprint_mm = 0.05, v;
    bool edge = true, radial = true;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *next = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            fputs(usage, stdout);
            return 0;
        } else if (!strcmp(a, "--k") && next) {
            if (!rs_parse_number(next, RS_PROFILE_FIT_MIN, RS_PROFILE_FIT_MAX, &v) || v != floor(v))
                return die("--k: want an integer 2..5");
            k = (int)v;
            i++;
        } else if (!strcmp(a, "--footprint") && next) {
            if (!rs_parse_number(next, 0.0, 10.0, &footprint_mm)) return die("--footprint: want mm in 0..10");
            i++;
        } else if (!strcmp(a, "--objective") && next) {
            edge = !strcmp(next, "edge") || !strcmp(next, "both");
            radial = !strcmp(next, "radial") || !strcmp(next, "both");
            if (!edge && !radial) return die("--objective: want edge, radial or both");
            i++;
        } else {
            fputs(usage, stderr);
            return 2;
        }
    }
    printf("# rouge-profile: K-Gaussian fits of d'Eon & Luebke's six-Gaussian skin profile (GPU Gems 3 ch. 14)\n");
    for (int kk = k ? k : 2; kk <= (k ? k : 4); kk++) {
        if (edge && fit_and_print(kk, footprint_mm, RS_PROFILE_FIT_EDGE)) return 2;
        if (radial && fit_and_print(kk, footprint_mm, RS_PROFILE_FIT_RADIAL)) return 2;
    }
    return 0;
}
