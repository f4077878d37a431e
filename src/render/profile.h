// profile.h — the skin diffusion profile as a sum of Gaussians, and its K-Gaussian fits for the mobile pipeline.
//
// Does: holds d'Eon & Luebke's six-Gaussian three-layer skin profile (GPU Gems 3 ch. 14); evaluates a Gaussian
// sum's radial profile R(r) and its response to a straight shadow edge (ESF); fits K = 2..5 Gaussians with
// variances shared by R, G, B and non-negative per-channel weights summing to 1 (energy preserving), and reports
// how far the fit is from the six-Gaussian sum. Pure CPU, deterministic, 1-5 ms a fit.
// Does not: blur images or touch GL (the render modules turn a profile into passes), or convert mm to pixels
// (callers pass the pixel footprint in mm).
//
//   rs_profile k3; rs_profile_fit_report rep; rs_error err = {0};
//   if (rs_profile_fit(3, 0.05, &k3, &rep, &err) != RS_OK) return err.code;
//   for (int i = 0; i < k3.count; i++)
//       blur_pass(k3.variance_mm2[i], k3.weight[i]);  // one blur per Gaussian, RGB weights
//   // rep.max_edge_error: worst |ESF_fit - ESF_6| over the three channels, fraction of the lit level
#ifndef RS_PROFILE_H
#define RS_PROFILE_H

#include "core/core.h"

#define RS_PROFILE_MAX 6
#define RS_PROFILE_FIT_MIN 2
#define RS_PROFILE_FIT_MAX 5
// The mobile pipeline's kernel count: K = 3 is the smallest whose worst-case edge error stays near 1/255.
#define RS_PROFILE_DEFAULT_COUNT 3

// R(r) = sum_i weight[i][c] G(variance_mm2[i], r), G(v, r) = exp(-r^2 / 2v) / (2 pi v) (GPU Gems 3 ch. 14).
// Gaussians sorted narrow to wide; weight[i] = {R, G, B}; each channel's weights sum to 1 (energy preserving).
typedef struct rs_profile {
    int count;
    float variance_mm2[RS_PROFILE_MAX];
    float weight[RS_PROFILE_MAX][3];
} rs_profile;

// d'Eon & Luebke's six Gaussians: variances 0.0064 .. 7.41 mm^2, weights of METHOD.md's table.
rs_profile rs_profile_deon(void);

// R(r) of one channel (0 R, 1 G, 2 B) at r_mm from the point of entry, in 1/mm^2 (integrates to 1 over the plane).
double rs_profile_radial(const rs_profile *p, int channel, double r_mm);

// Response of one channel to a straight shadow edge (lit for x > 0): the edge-spread function
//   ESF(x) = sum_i w_i (1 + erf(x / sqrt(2 (v_i + f^2)))) / 2,
// i.e. R integrated over the half-plane, pre-blurred by a pixel footprint Gaussian of sigma f = footprint_mm
// (convolving Gaussians adds variances). Goes 0 -> 1 for x -inf -> +inf, 0.5 at x = 0.
double rs_profile_edge_response(const rs_profile *p, int channel, double x_mm, double footprint_mm);

// Worst-case |ESF_a - ESF_b| over x in [-10, 10] mm per channel (fractions of the lit level; 1/255 = 0.0039),
// at the given footprint; returns the largest of the three.
double rs_profile_max_edge_error(const rs_profile *a, const rs_profile *b, double footprint_mm,
                                 double per_channel[3]);

// What a fit minimises; the weights are always the exact constrained least-squares optimum for the variances.
typedef enum rs_profile_objective {
    // Least squares on the edge response: integral of (ESF_fit - ESF_6)^2 dx (the default, see profile.c).
    RS_PROFILE_FIT_EDGE = 0,
    // Least squares on the radial profile over the plane: integral of (R_fit - R_6)^2 2 pi r dr.
    RS_PROFILE_FIT_RADIAL,
} rs_profile_objective;

typedef struct rs_profile_fit_report {
    double rms_radial[3];             // ||R_fit - R_6|| / ||R_6||, L2 over the plane, per channel, at the footprint
    double max_edge_error;            // rs_profile_max_edge_error vs the six Gaussians at the fit's footprint
    double max_edge_error_channel[3];
    int iterations;                   // Nelder-Mead iterations summed over starts (cost, not quality)
} rs_profile_fit_report;

// Fits k (RS_PROFILE_FIT_MIN..MAX) Gaussians to rs_profile_deon() with RS_PROFILE_FIT_EDGE, both profiles
// pre-blurred by a footprint Gaussian of sigma footprint_mm (>= 0; the renderer's half-pixel size in mm).
// Bad k or footprint -> RS_ERR_ARG, *out and *report untouched. report may be NULL.
rs_result rs_profile_fit(int k, double footprint_mm, rs_profile *out, rs_profile_fit_report *report,
                         rs_error *err);
// The same with a chosen objective (the README and bench compare both).
rs_result rs_profile_fit_objective(int k, double footprint_mm, rs_profile_objective objective, rs_profile *out,
                                   rs_profile_fit_report *report, rs_error *err);

#endif
