// profile.c — the six-Gaussian skin profile and its K-Gaussian fits (see profile.h).
//
// The fit is a variable projection: for fixed variances the best weights are a small convex problem
// (least squares with sum w = 1, w >= 0 per channel), solved exactly; an outer Nelder-Mead searches the K
// log-variances shared by R, G and B. Both objectives are integrals of squared differences of Gaussian sums,
// which have closed forms in the variances, so an evaluation costs a K x K Gram matrix and no sampling:
//   radial: integral over the plane of G(a, r) G(b, r) = 1 / (2 pi (a + b));
//   edge:   with s = sqrt(2a), t = sqrt(2b),
//           integral_0^inf erfc(x/s) erfc(x/t) dx = (s + t - sqrt(s^2 + t^2)) / sqrt(pi).
// The edge form holds because both sums have weights adding to 1: ESF_fit - ESF_6 = -1/2 sum c_j erfc(x / s_j)
// with sum c_j = 0, which is square-integrable, and it is odd in x, so the half line stands for the whole.
//
// Why the edge objective is the default (issue 5 asks for least squares on R(r)): least squares on R(r) over the
// plane is dominated by the narrow peak (||G(v)||^2 = 1 / (4 pi v), so G(0.0064) counts 1158x G(7.41)); it spends
// the K Gaussians on the first tenth of a millimetre and leaves the wide red tail, the part a shadow edge shows,
// off by 2.3% of the lit level at K = 3 (the edge fit: 0.7%; rouge-profile prints both). The ESF is R integrated
// over a half-plane, so least squares on it is still least squares on the radial profile, in the norm in which a
// shadow edge on screen differs: there a Gaussian's weight grows with its width (||erfc(x / s)||^2 ~ s) instead
// of shrinking with its area.
#include "render/profile.h"

#include <assert.h>
#include <math.h>
#include <string.h>

#define DEON_COUNT 6
#define PI 3.14159265358979323846
#define FIT_STARTS 3
#define NM_MAX_ITER 4000
// Log-variance search box, mm^2: well outside anything skin needs, so it only stops runaway simplices.
#define LOG_V_MIN (-9.2)  // 1e-4
#define LOG_V_MAX (4.6)   // 100
// Half width of the edge error scan, mm: the widest Gaussian (sigma 2.7 mm) has settled to 1e-4 by then.
#define EDGE_SCAN_MM 10.0
#define EDGE_SCAN_SAMPLES 4000

static const double deon_variance[DEON_COUNT] = { 0.0064, 0.0484, 0.187, 0.567, 1.99, 7.41 };
static const double deon_weight[DEON_COUNT][3] = {
    { 0.233, 0.455, 0.649 }, { 0.100, 0.336, 0.344 }, { 0.118, 0.198, 0.0 },
    { 0.113, 0.007, 0.007 }, { 0.358, 0.004, 0.0 },   { 0.078, 0.0, 0.0 },
};

rs_profile rs_profile_deon(void)
{
    rs_profile p = { .count = DEON_COUNT };
    for (int i = 0; i < DEON_COUNT; i++) {
        p.variance_mm2[i] = (float)deon_variance[i];
        for (int c = 0; c < 3; c++) p.weight[i][c] = (float)deon_weight[i][c];
    }
    return p;
}

static void check_profile(const rs_profile *p, int channel)
{
    assert(p && p->count >= 1 && p->count <= RS_PROFILE_MAX);
    assert(channel >= 0 && channel < 3);
    (void)p;
    (void)channel;
}

double rs_profile_radial(const rs_profile *p, int channel, double r_mm)
{
    check_profile(p, channel);
    double sum = 0.0;
    for (int i = 0; i < p->count; i++) {
        double v = p->variance_mm2[i];
        if (v > 0.0) sum += p->weight[i][channel] * exp(-r_mm * r_mm / (2.0 * v)) / (2.0 * PI * v);
    }
    return sum;
}

// (1 + erf(x / s)) / 2 with s = sqrt(2 v); v = 0 is a hard step.
static double edge_step(double x_mm, double v)
{
    if (v <= 0.0) return x_mm > 0.0 ? 1.0 : x_mm < 0.0 ? 0.0 : 0.5;
    return 0.5 * (1.0 + erf(x_mm / sqrt(2.0 * v)));
}

double rs_profile_edge_response(const rs_profile *p, int channel, double x_mm, double footprint_mm)
{
    check_profile(p, channel);
    double vp = footprint_mm * footprint_mm, sum = 0.0;
    for (int i = 0; i < p->count; i++) sum += p->weight[i][channel] * edge_step(x_mm, p->variance_mm2[i] + vp);
    return sum;
}

double rs_profile_max_edge_error(const rs_profile *a, const rs_profile *b, double footprint_mm,
                                 double per_channel[3])
{
    check_profile(a, 0);
    check_profile(b, 0);
    double vp = footprint_mm * footprint_mm, worst[3] = { 0 };
    // Samples crowd towards the edge (x = 10 t^2 mm), where the narrow Gaussians differ: spacing 0.6 um at
    // 0.01 mm, 3 um at 1 mm. Each step is evaluated once and mirrored, (1 + erf(-y)) / 2 = 1 - (1 + erf(y)) / 2.
    for (int k = 0; k <= EDGE_SCAN_SAMPLES; k++) {
        double t = (double)k / EDGE_SCAN_SAMPLES, x = EDGE_SCAN_MM * t * t;
        double pos[3] = { 0 }, neg[3] = { 0 };
        for (int side = 0; side < 2; side++) {
            const rs_profile *p = side ? b : a;
            double sign = side ? -1.0 : 1.0;
            for (int i = 0; i < p->count; i++) {
                double s = edge_step(x, p->variance_mm2[i] + vp);
                for (int c = 0; c < 3; c++) {
                    pos[c] += sign * p->weight[i][c] * s;
                    neg[c] += sign * p->weight[i][c] * (1.0 - s);
                }
            }
        }
        for (int c = 0; c < 3; c++) worst[c] = fmax(worst[c], fmax(fabs(pos[c]), fabs(neg[c])));
    }
    if (per_channel) memcpy(per_channel, worst, sizeof worst);
    return fmax(worst[0], fmax(worst[1], worst[2]));
}

// ---- the fit ----

// Everything one objective evaluation needs: the target (six Gaussians, footprint included) and its norms.
typedef struct fit_problem {
    rs_profile_objective objective;
    double vp;                       // footprint variance, mm^2
    double ref_v[DEON_COUNT];        // target variances + vp
    double ref_w[DEON_COUNT][3];     // target weights, each channel normalised to sum 1
    double ref_norm2[3];             // ||target||^2 per channel
    unsigned support[3];             // per channel, the last optimal weight support (a hint, bit i = Gaussian i)
} fit_problem;

// Inner product of two unit-weight Gaussians of variances a, b (footprint included) in the objective's norm.
static double gauss_dot(rs_profile_objective objective, double a, double b)
{
    if (objective == RS_PROFILE_FIT_RADIAL) return 1.0 / (2.0 * PI * (a + b));
    // Edge: erfc(x / s) erfc(x / t) over x >= 0 (the 1/4 of ESF = (1 + erf) / 2 and the odd mirror are
    // constant factors and dropped).
    double s = sqrt(2.0 * a), t = sqrt(2.0 * b);
    return (s + t - sqrt(s * s + t * t)) / sqrt(PI);
}

// Solves the (n x n) system m x = rhs in place by Gaussian elimination with partial pivoting; false when
// (numerically) singular, which happens when two variances nearly coincide.
static bool solve_small(int n, double m[RS_PROFILE_MAX + 1][RS_PROFILE_MAX + 1], double rhs[RS_PROFILE_MAX + 1])
{
    double scale = 0.0;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) scale = fmax(scale, fabs(m[i][j]));
    for (int col = 0; col < n; col++) {
        int piv = col;
        for (int r = col + 1; r < n; r++)
            if (fabs(m[r][col]) > fabs(m[piv][col])) piv = r;
        if (!(fabs(m[piv][col]) > 1e-13 * scale)) return false;
        if (piv != col) {
            for (int j = 0; j < n; j++) {
                double t = m[col][j];
                m[col][j] = m[piv][j];
                m[piv][j] = t;
            }
            double t = rhs[col];
            rhs[col] = rhs[piv];
            rhs[piv] = t;
        }
        for (int r = col + 1; r < n; r++) {
            double f = m[r][col] / m[col][col];
            for (int j = col; j < n; j++) m[r][j] -= f * m[col][j];
            rhs[r] -= f * rhs[col];
        }
    }
    for (int i = n - 1; i >= 0; i--) {
        double s = rhs[i];
        for (int j = i + 1; j < n; j++) s -= m[i][j] * rhs[j];
        rhs[i] = s / m[i][i];
    }
    return true;
}

// Equality-constrained least squares on the support `mask`: solves the KKT system
// [H_SS 1; 1' 0] [w_S; lambda] = [g_S; 1] (stationarity of w'Hw - 2 g'w + 2 lambda (1'w - 1)). Returns true when
// the solution is the optimum of the whole problem min w'Hw - 2 g'w, sum w = 1, w >= 0: w_S >= 0 and no weight off
// the support would lower the objective, (Hw - g)_i + lambda >= 0 (the KKT conditions; the problem is convex, so
// they are sufficient). *feasible says whether w >= 0 at least.
static bool solve_support(int k, unsigned mask, const double h[RS_PROFILE_MAX][RS_PROFILE_MAX],
                          const double g[RS_PROFILE_MAX], double w[RS_PROFILE_MAX], bool *feasible)
{
    int idx[RS_PROFILE_MAX], n = 0;
    for (int i = 0; i < k; i++)
        if (mask & (1u << i)) idx[n++] = i;
    double m[RS_PROFILE_MAX + 1][RS_PROFILE_MAX + 1], x[RS_PROFILE_MAX + 1];
    for (int i = 0; i < n; i++) {
        for (int j = 0; j < n; j++) m[i][j] = h[idx[i]][idx[j]];
        m[i][n] = m[n][i] = 1.0;
        x[i] = g[idx[i]];
    }
    m[n][n] = 0.0;
    x[n] = 1.0;
    *feasible = false;
    if (!solve_small(n + 1, m, x)) return false;
    for (int i = 0; i < k; i++) w[i] = 0.0;
    for (int i = 0; i < n; i++) {
        if (x[i] < 0.0) return false;
        w[idx[i]] = x[i];
    }
    *feasible = true;
    double lambda = x[n], scale = fabs(lambda);
    for (int i = 0; i < k; i++) scale = fmax(scale, fabs(g[i]));
    for (int i = 0; i < k; i++) {
        if (mask & (1u << i)) continue;
        double grad = lambda - g[i];
        for (int j = 0; j < k; j++) grad += h[i][j] * w[j];
        if (grad < -1e-12 * scale) return false;
    }
    return true;
}

// min_w w'Hw - 2 g'w + c subject to sum w = 1, w >= 0 (k <= 5), exactly. The optimum is the equality-constrained
// optimum on its own support, so trying supports until one passes the KKT test finds it; the caller's *support
// (last evaluation's answer, which Nelder-Mead's small steps rarely change) is tried first, then all 2^k - 1 in
// order. Should round-off fail every KKT test, the best non-negative candidate stands. Returns the residual.
static double constrained_lsq(int k, const double h[RS_PROFILE_MAX][RS_PROFILE_MAX], const double g[RS_PROFILE_MAX],
                              double c, unsigned *support, double w_out[RS_PROFILE_MAX])
{
    double best = INFINITY;
    unsigned full = (1u << k) - 1u;
    for (unsigned t = 0; t <= full; t++) {
        unsigned mask = t == 0 ? *support & full : t;
        if (mask == 0 || (t > 0 && mask == (*support & full))) continue;
        double w[RS_PROFILE_MAX];
        bool feasible, optimal = solve_support(k, mask, h, g, w, &feasible);
        if (!feasible) continue;
        double f = c;
        for (int i = 0; i < k; i++) {
            f -= 2.0 * g[i] * w[i];
            for (int j = 0; j < k; j++) f += w[i] * h[i][j] * w[j];
        }
        if (optimal || f < best) {
            best = f;
            memcpy(w_out, w, sizeof w);
            *support = mask;
        }
        if (optimal) break;
    }
    // A single Gaussian (w = 1) is always a non-singular, feasible candidate, so best is finite.
    return fmax(best, 0.0);
}

// The variable-projection objective: best weights for exp(log_v), residual summed over channels relative to
// the target's norm. Fills weight when non-NULL.
static double fit_objective(fit_problem *fp, int k, const double log_v[RS_PROFILE_MAX],
                            double weight[RS_PROFILE_MAX][3])
{
    double v[RS_PROFILE_MAX], penalty = 0.0;
    for (int i = 0; i < k; i++) {
        double y = RS_CLAMP(log_v[i], LOG_V_MIN, LOG_V_MAX);
        penalty += (log_v[i] - y) * (log_v[i] - y);
        v[i] = exp(y) + fp->vp;
    }
    double h[RS_PROFILE_MAX][RS_PROFILE_MAX], cross[RS_PROFILE_MAX][DEON_COUNT];
    for (int i = 0; i < k; i++) {
        for (int j = 0; j < k; j++) h[i][j] = gauss_dot(fp->objective, v[i], v[j]);
        for (int j = 0; j < DEON_COUNT; j++) cross[i][j] = gauss_dot(fp->objective, v[i], fp->ref_v[j]);
    }
    double total = 0.0, norm = 0.0;
    for (int c = 0; c < 3; c++) {
        double g[RS_PROFILE_MAX], w[RS_PROFILE_MAX];
        for (int i = 0; i < k; i++) {
            g[i] = 0.0;
            for (int j = 0; j < DEON_COUNT; j++) g[i] += cross[i][j] * fp->ref_w[j][c];
        }
        double f = constrained_lsq(k, h, g, fp->ref_norm2[c], &fp->support[c], w);
        if (weight)
            for (int i = 0; i < k; i++) weight[i][c] = w[i];
        total += f;
        norm += fp->ref_norm2[c];
    }
    return total / norm + penalty;
}

// Nelder-Mead (reflection 1, expansion 2, contraction 1/2, shrink 1/2) from x with initial steps `step`
// (log-variance units); x receives the best vertex. Deterministic. Returns iterations used.
static int nelder_mead(fit_problem *fp, int k, double x[RS_PROFILE_MAX], double step, double *f_out)
{
    double simplex[RS_PROFILE_MAX + 1][RS_PROFILE_MAX], f[RS_PROFILE_MAX + 1];
    for (int p = 0; p <= k; p++) {
        memcpy(simplex[p], x, sizeof(double) * (size_t)k);
        if (p > 0) simplex[p][p - 1] += step;
        f[p] = fit_objective(fp, k, simplex[p], NULL);
    }
    int iter = 0;
    for (; iter < NM_MAX_ITER; iter++) {
        // Order: best first, worst last (insertion sort keeps ties in vertex order: deterministic).
        for (int i = 1; i <= k; i++)
            for (int j = i; j > 0 && f[j] < f[j - 1]; j--) {
                double tf = f[j], tx[RS_PROFILE_MAX];
                f[j] = f[j - 1];
                f[j - 1] = tf;
                memcpy(tx, simplex[j], sizeof tx);
                memcpy(simplex[j], simplex[j - 1], sizeof tx);
                memcpy(simplex[j - 1], tx, sizeof tx);
            }
        double size = 0.0;
        for (int p = 1; p <= k; p++)
            for (int i = 0; i < k; i++) size = fmax(size, fabs(simplex[p][i] - simplex[0][i]));
        if (size < 1e-7 || f[k] - f[0] <= 1e-12 * f[0]) break;

        double centroid[RS_PROFILE_MAX] = { 0 }, xr[RS_PROFILE_MAX], xt[RS_PROFILE_MAX];
        for (int p = 0; p < k; p++)
            for (int i = 0; i < k; i++) centroid[i] += simplex[p][i] / k;
        for (int i = 0; i < k; i++) xr[i] = centroid[i] + (centroid[i] - simplex[k][i]);
        double fr = fit_objective(fp, k, xr, NULL);
        if (fr < f[0]) {
            for (int i = 0; i < k; i++) xt[i] = centroid[i] + 2.0 * (centroid[i] - simplex[k][i]);
            double fe = fit_objective(fp, k, xt, NULL);
            bool expand = fe < fr;
            memcpy(simplex[k], expand ? xt : xr, sizeof xr);
            f[k] = expand ? fe : fr;
            continue;
        }
        if (fr < f[k - 1]) {
            memcpy(simplex[k], xr, sizeof xr);
            f[k] = fr;
            continue;
        }
        // Contract towards the better of the worst vertex and its reflection.
        bool outside = fr < f[k];
        for (int i = 0; i < k; i++)
            xt[i] = centroid[i] + 0.5 * ((outside ? xr[i] : simplex[k][i]) - centroid[i]);
        double fc = fit_objective(fp, k, xt, NULL);
        if (fc < (outside ? fr : f[k])) {
            memcpy(simplex[k], xt, sizeof xt);
            f[k] = fc;
            continue;
        }
        for (int p = 1; p <= k; p++) {
            for (int i = 0; i < k; i++) simplex[p][i] = simplex[0][i] + 0.5 * (simplex[p][i] - simplex[0][i]);
            f[p] = fit_objective(fp, k, simplex[p], NULL);
        }
    }
    int best = 0;
    for (int p = 1; p <= k; p++)
        if (f[p] < f[best]) best = p;
    memcpy(x, simplex[best], sizeof(double) * (size_t)k);
    *f_out = f[best];
    return iter;
}

static void fit_problem_init(fit_problem *fp, rs_profile_objective objective, double footprint_mm)
{
    memset(fp, 0, sizeof *fp);
    fp->objective = objective;
    fp->vp = footprint_mm * footprint_mm;
    for (int c = 0; c < 3; c++) {
        // The table's weights add to 1.000 in decimal; make it exact so the edge form's sum c_j = 0 holds.
        double sum = 0.0;
        for (int j = 0; j < DEON_COUNT; j++) sum += deon_weight[j][c];
        for (int j = 0; j < DEON_COUNT; j++) fp->ref_w[j][c] = deon_weight[j][c] / sum;
    }
    for (int j = 0; j < DEON_COUNT; j++) fp->ref_v[j] = deon_variance[j] + fp->vp;
    for (int c = 0; c < 3; c++) {
        double n2 = 0.0;
        for (int i = 0; i < DEON_COUNT; i++)
            for (int j = 0; j < DEON_COUNT; j++)
                n2 += fp->ref_w[i][c] * fp->ref_w[j][c] * gauss_dot(objective, fp->ref_v[i], fp->ref_v[j]);
        fp->ref_norm2[c] = n2;
    }
}

rs_result rs_profile_fit_objective(int k, double footprint_mm, rs_profile_objective objective, rs_profile *out,
                                   rs_profile_fit_report *report, rs_error *err)
{
    assert(out);
    if (k < RS_PROFILE_FIT_MIN || k > RS_PROFILE_FIT_MAX)
        return rs_fail(err, RS_ERR_ARG, "profile fit: k = %d, want %d..%d Gaussians", k, RS_PROFILE_FIT_MIN,
                       RS_PROFILE_FIT_MAX);
    if (!(footprint_mm >= 0.0 && footprint_mm <= 10.0))
        return rs_fail(err, RS_ERR_ARG, "profile fit: footprint %g mm, want 0..10 mm", footprint_mm);
    if (objective != RS_PROFILE_FIT_EDGE && objective != RS_PROFILE_FIT_RADIAL)
        return rs_fail(err, RS_ERR_ARG, "profile fit: unknown objective %d", (int)objective);

    fit_problem fp;
    fit_problem_init(&fp, objective, footprint_mm);
    // Starts: k variances log-spaced over three spans of the six-Gaussian table (all of it, its narrow part,
    // its wide part); each is polished by restarting Nelder-Mead at its optimum until that stops paying, the
    // usual cure for simplices that collapse early. The best start wins.
    static const double spans[FIT_STARTS][2] = { { 0.0064, 7.41 }, { 0.0064, 1.99 }, { 0.0484, 7.41 } };
    double best_x[RS_PROFILE_MAX] = { 0 }, best_f = INFINITY;
    int iterations = 0;
    for (int s = 0; s < FIT_STARTS; s++) {
        double x[RS_PROFILE_MAX], f = INFINITY;
        double lo = log(spans[s][0]), hi = log(spans[s][1]);
        for (int i = 0; i < k; i++) x[i] = lo + (hi - lo) * i / (k - 1);
        for (int restart = 0; restart < 4; restart++) {
            double before = f;
            iterations += nelder_mead(&fp, k, x, restart == 0 ? 0.7 : 0.2, &f);
            if (!(f < before * (1.0 - 1e-9))) break;
        }
        if (f < best_f) {
            best_f = f;
            memcpy(best_x, x, sizeof x);
        }
    }

    // Sort narrow to wide, then take the weights of the final variances.
    for (int i = 1; i < k; i++)
        for (int j = i; j > 0 && best_x[j] < best_x[j - 1]; j--) {
            double t = best_x[j];
            best_x[j] = best_x[j - 1];
            best_x[j - 1] = t;
        }
    double weight[RS_PROFILE_MAX][3];
    fit_objective(&fp, k, best_x, weight);
    rs_profile fit = { .count = k };
    for (int i = 0; i < k; i++) {
        fit.variance_mm2[i] = (float)exp(RS_CLAMP(best_x[i], LOG_V_MIN, LOG_V_MAX));
        for (int c = 0; c < 3; c++) fit.weight[i][c] = (float)weight[i][c];
    }

    if (report) {
        rs_profile_fit_report rep = { .iterations = iterations };
        rs_profile deon = rs_profile_deon();
        rep.max_edge_error = rs_profile_max_edge_error(&fit, &deon, footprint_mm, rep.max_edge_error_channel);
        // The radial error in its own norm, whatever the objective was.
        fit_problem radial;
        fit_problem_init(&radial, RS_PROFILE_FIT_RADIAL, footprint_mm);
        for (int c = 0; c < 3; c++) {
            double d2 = 0.0;
            for (int i = 0; i < k + DEON_COUNT; i++)
                for (int j = 0; j < k + DEON_COUNT; j++) {
                    double vi = i < k ? fit.variance_mm2[i] + radial.vp : radial.ref_v[i - k];
                    double vj = j < k ? fit.variance_mm2[j] + radial.vp : radial.ref_v[j - k];
                    double wi = i < k ? fit.weight[i][c] : -radial.ref_w[i - k][c];
                    double wj = j < k ? fit.weight[j][c] : -radial.ref_w[j - k][c];
                    d2 += wi * wj * gauss_dot(RS_PROFILE_FIT_RADIAL, vi, vj);
                }
            rep.rms_radial[c] = sqrt(fmax(d2, 0.0) / radial.ref_norm2[c]);
        }
        *report = rep;
    }
    *out = fit;
    return RS_OK;
}

rs_result rs_profile_fit(int k, double footprint_mm, rs_profile *out, rs_profile_fit_report *report,
                         rs_error *err)
{
    return rs_profile_fit_objective(k, footprint_mm, RS_PROFILE_FIT_EDGE, out, report, err);
}
