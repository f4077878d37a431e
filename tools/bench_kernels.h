// bench_kernels.h — the CPU-side work that `make bench` times in more than one program: rouge-bench's rows
// and rouge-cpubench (the same work natively and as WebAssembly, for the wasm/native ratio). Header-only:
// each bench is one translation unit.
#ifndef RS_TOOLS_BENCH_KERNELS_H
#define RS_TOOLS_BENCH_KERNELS_H

#include "makeup/makeup.h"
#include "splat/splat.h"

#include <stdlib.h>
#include <string.h>

static int bench_cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

// Median (sorts in place); the mean of the two middle values for even n.
static double bench_median(double *v, int n)
{
    if (n <= 0) return 0.0 / 0.0;
    qsort(v, (size_t)n, sizeof *v, bench_cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Splats a person would paint: a skin region of the face (not `other`) facing the camera.
static uint32_t bench_face_candidates(const rs_splat_cloud *c, uint32_t **out)
{
    uint32_t n = c->hdr.count, k = 0;
    uint32_t *idx = rs_alloc_array(n, sizeof *idx);
    if (!idx) return 0;
    const float *fw = c->hdr.forward;
    for (uint32_t i = 0; i < n; i++) {
        uint8_t region = (uint8_t)(c->packed[i].w[1] >> 24);
        const float *nm = c->normal[i];
        if (region != RS_REGION_OTHER && nm[0] * fw[0] + nm[1] * fw[1] + nm[2] * fw[2] > 0.5f) idx[k++] = i;
    }
    if (k == 0) {  // a face without regions: anything facing forward
        for (uint32_t i = 0; i < n; i++) {
            const float *nm = c->normal[i];
            if (nm[0] * fw[0] + nm[1] * fw[1] + nm[2] * fw[2] > 0.5f) idx[k++] = i;
        }
    }
    *out = idx;
    return k;
}

// `stamps` blush stamps of brush size `size` (a fraction of the face height) at pseudo-random face
// positions, in strokes of 16: each stamp's µs and splats touched into us[] / touched[].
static rs_result bench_stamps(const rs_splat_cloud *c, rs_makeup *mk, const uint32_t *cand, uint32_t ncand,
                              float size, int stamps, double *us, double *touched, rs_error *err)
{
    enum { STROKE = 16 };
    const rs_cosmetic *blush = rs_cosmetic_find("blush");
    if (!blush || ncand == 0) return rs_fail(err, RS_ERR_ARG, "no face splats / no blush preset");
    uint64_t seed = 0x9E3779B97F4A7C15u;
    rs_makeup_range dirty;
    rs_makeup_reset(mk, &dirty);
    rs_makeup_stamp_desc d = {.opacity = 0.5f, .pressure = 1.0f, .cosmetic = blush,
                              .radius = rs_makeup_brush_radius(&c->hdr, size)};
    memcpy(d.view_dir, c->hdr.forward, sizeof d.view_dir);
    rs_result r = RS_OK;
    for (int i = 0; i < stamps && !r; i++) {
        if (i % STROKE == 0) rs_makeup_begin_stroke(mk);
        seed = seed * 6364136223846793005u + 1442695040888963407u;
        uint32_t at = cand[(uint32_t)(seed >> 33) % ncand];
        memcpy(d.pos, c->pos[at], sizeof d.pos);
        rs_makeup_stamp_info info;
        double t0 = rs_time_now();
        r = rs_makeup_stamp(mk, &d, &info, err);
        us[i] = (rs_time_now() - t0) * 1e6;
        touched[i] = info.touched;
        if (i % STROKE == STROKE - 1 || i == stamps - 1) {
            if (!r) r = rs_makeup_end_stroke(mk, err);
            rs_makeup_forget_history(mk);  // keep the undo history from growing over the run
        }
    }
    return r;
}

#endif
