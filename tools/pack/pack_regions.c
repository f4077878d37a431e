// pack_regions.c — face regions by geometry relative to the landmarks (see pack.h, docs/regions.md).
//
// A template in face coordinates: for a point p, ds = (p - nose tip) . side / H, du = (...) . up / H and
// df = (...) . forward / H, with H the face height (vertex to menton). The lips follow the detected lip
// line (a parabola through the mouth corners and the stomion); the nose, cheeks and forehead are boxes
// and tapers placed at anthropometric offsets from the nose tip and the brow (glabella), with limits on
// depth (df) and facing (normal . forward) that keep them on the front of the face; brows and eyelids
// hang from the brow line (glabella) on either side of the mid-line. Order of precedence: lips,
// brow, eyelid, nose, cheek, forehead; everything else is `other`.
#include "pack/pack.h"

#include <math.h>

static float dot3(const float a[3], const float b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

typedef struct frame {
    const rs_pack_face *f;
    float H;
    float nose[3];        // nose tip in (s, u, f)
    float mouth_s, mouth_u, half_w;  // mouth centre and half width (model units)
    float a, b, c;        // lip line u(s) = a + b t + c t^2, t = s - mouth_s
    float brow_du;
} frame;

static void to_face(const rs_pack_face *f, const float p[3], float out[3])
{
    out[0] = dot3(p, f->side);
    out[1] = dot3(p, f->up);
    out[2] = dot3(p, f->forward);
}

static uint8_t classify(const frame *fr, const float p[3], const float n[3])
{
    const rs_pack_face *f = fr->f;
    float q[3];
    to_face(f, p, q);
    float H = fr->H;
    float ds = (q[0] - fr->nose[0]) / H, du = (q[1] - fr->nose[1]) / H, df = (q[2] - fr->nose[2]) / H;
    float facing = n ? dot3(n, f->forward) : 1.0f, ads = fabsf(ds);
    // Nothing on the face looks backwards or lies deeper than the ears.
    if (facing < -0.2f || df < -0.45f) return RS_REGION_OTHER;

    // Lips: between the lip line and the vermilion borders, whose height shrinks toward the corners;
    // a small constant keeps the corners themselves inside.
    float t = (q[0] - fr->mouth_s) / fr->half_w;
    if (fabsf(t) <= 1.08f && df > -0.16f) {
        float line = fr->a + fr->b * (q[0] - fr->mouth_s) + fr->c * (q[0] - fr->mouth_s) * (q[0] - fr->mouth_s);
        float k = sqrtf(fmaxf(0.0f, 1.0f - t * t)), dv = (q[1] - line) / H;
        if (dv <= 0.036f * k + 0.007f && dv >= -(0.018f * k + 0.005f)) return RS_REGION_LIPS;
    }
    // Brows: an arched band over each orbit, highest above the middle of the eye and dropping toward the
    // tail; the hairs sit ~3 % H below the glabella (measured on the bundled head, see docs/regions.md).
    if (ads >= 0.045f && ads <= 0.25f && facing > 0.0f && df > -0.3f) {
        float centre = fr->brow_du - 0.031f - 1.6f * (ads - 0.14f) * (ads - 0.14f);
        if (fabsf(du - centre) <= 0.019f) return RS_REGION_BROW;
    }
    // Eyelids: the eye area around each eye (centre ~0.105 H below the glabella, 0.12 H beside the
    // mid-line), from below the lower lash line up to the brow, where shadow and liner go. Before the
    // nose, which would otherwise take the inner corners.
    float lx = (ads - 0.12f) / 0.09f, dv = du - (fr->brow_du - 0.105f), ly = dv / (dv > 0.0f ? 0.085f : 0.05f);
    if (ads >= 0.04f && lx * lx + ly * ly <= 1.0f && facing > -0.1f && df > -0.3f) return RS_REGION_EYELID;
    // Nose: from just below the tip (columella, alae) up to the nasion, narrowing toward the top.
    if (du >= -0.065f && du <= fr->brow_du - 0.03f && df > -0.11f - 0.05f * fmaxf(du, 0.0f) / 0.16f) {
        float half = du < 0.02f ? 0.075f : 0.075f - 0.04f * fminf(1.0f, (du - 0.02f) / 0.14f);
        if (ads <= half) return RS_REGION_NOSE;
    }
    // Cheeks: an ellipse over the cheekbone and the cheek's hollow, beside the nose and the mouth, below
    // the eyes; the nasolabial side stops at the nose wing and a little outside the mouth corners.
    float mouth_du = (fr->mouth_u - fr->nose[1]) / H, corner_ds = fr->half_w / H;
    float ex = (ads - 0.155f) / 0.12f, ey = (du + 0.05f) / 0.115f;
    if (ex * ex + ey * ey <= 1.0f && ads >= (du < mouth_du + 0.05f ? corner_ds + 0.02f : 0.085f) && facing > -0.1f &&
        df > -0.3f)
        return RS_REGION_CHEEK;
    // Forehead: a half ellipse above the brows (glabella), while the surface still faces forward.
    float fy = (du - fr->brow_du - 0.02f) / 0.22f, fx = ads / 0.21f;
    if (fy >= 0 && fx * fx + fy * fy <= 1.0f && facing > 0.4f) return RS_REGION_FOREHEAD;
    return RS_REGION_OTHER;
}

void rs_pack_segment(const float (*pos)[3], const float (*normal)[3], uint32_t count,
                     const rs_pack_face *face, uint8_t *region)
{
    if (!face->found) {
        for (uint32_t i = 0; i < count; i++)
            if (region[i] == RS_PACK_REGION_AUTO) region[i] = RS_REGION_OTHER;
        return;
    }
    frame fr = {.f = face, .H = face->face_height, .brow_du = face->brow_y / face->face_height};
    to_face(face, face->nose_tip, fr.nose);
    float m[3], l[3], r[3];
    to_face(face, face->mouth, m);
    to_face(face, face->mouth_corner[1], l);
    to_face(face, face->mouth_corner[0], r);
    fr.mouth_s = m[0];
    fr.mouth_u = m[1];
    fr.half_w = fmaxf(0.5f * (l[0] - r[0]), 0.02f * fr.H);
    // Lip line through the corners and the stomion: u = a + b t + c t^2 with t = s - mouth_s.
    float tl = l[0] - m[0], tr = r[0] - m[0];
    fr.a = m[1];
    if (fabsf(tl) > 1e-6f && fabsf(tr) > 1e-6f && fabsf(tl - tr) > 1e-6f) {
        float yl = (l[1] - m[1]) / tl, yr = (r[1] - m[1]) / tr;  // (u - a) / t = b + c t
        fr.c = (yl - yr) / (tl - tr);
        fr.b = yl - fr.c * tl;
    }
    for (uint32_t i = 0; i < count; i++)
        if (region[i] == RS_PACK_REGION_AUTO) region[i] = classify(&fr, pos[i], normal ? normal[i] : NULL);
}
