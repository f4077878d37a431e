// pack_face.c — face frame and landmarks of a front-facing head scan (see pack.h, docs/regions.md).
//
// Everything is found on a "front height map": the scan seen from the front along `forward`, each cell
// keeping the most forward surface (f = p . forward) over a grid in (s, u) = (p . side, p . up). On it:
//   1. the silhouette's row widths give the top of the head, the head's mid-line and width, and the
//      first narrowing below the head (neck or chin), hence a rough head size H0;
//   2. the nose tip is the cell of the upper-middle face that stands out most from a ring around it
//      (the nose is narrow and protrudes ~2 cm; the chin and brows are broad, the cheeks recede);
//   3. face height H = (top - nose tip) / VERTEX_TO_NOSE (vertex-pronasale is ~0.6 of vertex-menton,
//      measured along up);
//   4. along the mid-line profile below the nose: the stomion is the crease (a valley at 1.2% H scale)
//      nearest 0.145 H below the nose tip; the mouth corners end the lip crease traced sideways from it;
//      above the nose: the nasion (deepest point) and the glabella (the brow bump above it).
#include "pack/pack.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

// Vertex to nose tip over vertex to menton, measured along up. The bundled head's menton is 4.75 units
// below its vertex (data README); along the data's +Y the tip is 0.605 of it down, along the facial
// frame rs_pack_orient finds (3 deg tilted back) 0.578, the value used: that frame is the default.
#define VERTEX_TO_NOSE 0.578f

rs_pack_axis rs_pack_axis_parse(const char *s)
{
    if (!s) return RS_PACK_AXIS_DEFAULT;
    int sign = 1;
    if (*s == '+' || *s == '-') sign = *s++ == '-' ? -1 : 1;
    if (s[0] == 0 || s[1] != 0) return RS_PACK_AXIS_DEFAULT;
    switch (s[0]) {
    case 'x': case 'X': return sign > 0 ? RS_PACK_AXIS_POS_X : RS_PACK_AXIS_NEG_X;
    case 'y': case 'Y': return sign > 0 ? RS_PACK_AXIS_POS_Y : RS_PACK_AXIS_NEG_Y;
    case 'z': case 'Z': return sign > 0 ? RS_PACK_AXIS_POS_Z : RS_PACK_AXIS_NEG_Z;
    default: return RS_PACK_AXIS_DEFAULT;
    }
}

static void axis_vector(rs_pack_axis a, rs_pack_axis fallback, float v[3])
{
    if (a == RS_PACK_AXIS_DEFAULT) a = fallback;
    int k = (a - 1) / 2;
    v[0] = v[1] = v[2] = 0;
    v[k] = (a - 1) % 2 ? -1.0f : 1.0f;
}

static float dot3(const float a[3], const float b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

// ---- the front height map ----

typedef struct hmap {
    int w, h;          // cells along s and u
    float s0, u0, cell;
    float *f;          // forward coordinate of the front-most surface, -INFINITY where empty
    float ring[16][2]; // cos, sin of the 16 directions protrusion() samples (computed once)
} hmap;

static float hm_get(const hmap *m, int x, int y)
{
    if (x < 0 || y < 0 || x >= m->w || y >= m->h) return -INFINITY;
    return m->f[(size_t)y * m->w + x];
}

static int hm_x(const hmap *m, float s)
{
    return (int)floorf((s - m->s0) / m->cell);
}

static int hm_y(const hmap *m, float u)
{
    return (int)floorf((u - m->u0) / m->cell);
}

// Value at a point, bilinear over the four nearest cells that are filled.
static float hm_at(const hmap *m, float s, float u)
{
    float x = (s - m->s0) / m->cell - 0.5f, y = (u - m->u0) / m->cell - 0.5f;
    int x0 = (int)floorf(x), y0 = (int)floorf(y);
    float fx = x - x0, fy = y - y0, sum = 0, wsum = 0;
    for (int k = 0; k < 4; k++) {
        float v = hm_get(m, x0 + (k & 1), y0 + (k >> 1));
        float w = ((k & 1) ? fx : 1 - fx) * ((k >> 1) ? fy : 1 - fy);
        if (v == -INFINITY) continue;
        sum += w * v;
        wsum += w;
    }
    return wsum > 1e-6f ? sum / wsum : -INFINITY;
}

// Fills empty cells that have at least 3 filled neighbours with their mean; `passes` times. Closes the
// gaps a sparse cloud leaves between points without growing the silhouette much.
static void hm_fill(hmap *m, int passes, float *tmp)
{
    for (int p = 0; p < passes; p++) {
        memcpy(tmp, m->f, (size_t)m->w * m->h * sizeof *tmp);
        for (int y = 0; y < m->h; y++)
            for (int x = 0; x < m->w; x++) {
                if (tmp[(size_t)y * m->w + x] != -INFINITY) continue;
                float sum = 0;
                int n = 0;
                for (int dy = -1; dy <= 1; dy++)
                    for (int dx = -1; dx <= 1; dx++) {
                        int xx = x + dx, yy = y + dy;
                        if (xx < 0 || yy < 0 || xx >= m->w || yy >= m->h) continue;
                        float v = tmp[(size_t)yy * m->w + xx];
                        if (v != -INFINITY) sum += v, n++;
                    }
                if (n >= 3) m->f[(size_t)y * m->w + x] = sum / n;
            }
    }
}

// Separable box blur of radius r cells over filled cells only (empty ones stay empty).
static void hm_blur(hmap *m, int r, float *tmp)
{
    if (r <= 0) return;
    for (int pass = 0; pass < 2; pass++) {
        memcpy(tmp, m->f, (size_t)m->w * m->h * sizeof *tmp);
        for (int y = 0; y < m->h; y++)
            for (int x = 0; x < m->w; x++) {
                if (tmp[(size_t)y * m->w + x] == -INFINITY) continue;
                float sum = 0;
                int n = 0;
                for (int d = -r; d <= r; d++) {
                    int xx = pass ? x : x + d, yy = pass ? y + d : y;
                    if (xx < 0 || yy < 0 || xx >= m->w || yy >= m->h) continue;
                    float v = tmp[(size_t)yy * m->w + xx];
                    if (v != -INFINITY) sum += v, n++;
                }
                m->f[(size_t)y * m->w + x] = sum / n;
            }
    }
}

// ---- landmarks ----

// How far the surface at (s, u) stands in front of a ring of radius rho around it: f minus the largest
// of 16 ring samples. Narrow bumps (the nose) score high; broad ones (brow, chin, cheeks) do not.
// A search for the largest passes the best so far as `beat`: once the samples seen rule out beating it
// (the answer only falls as samples come), -INFINITY comes back at once, as for a ring off the surface.
static float protrusion(const hmap *m, float s, float u, float rho, float beat)
{
    float c = hm_at(m, s, u);
    if (c == -INFINITY) return -INFINITY;
    float best = -INFINITY;
    int seen = 0;
    for (int k = 0; k < 16; k++) {
        float v = hm_at(m, s + rho * m->ring[k][0], u + rho * m->ring[k][1]);
        if (v == -INFINITY) continue;
        best = fmaxf(best, v);
        seen++;
        if (c - best <= beat) return -INFINITY;
    }
    return seen >= 12 ? c - best : -INFINITY;  // the ring must lie mostly on the surface
}

// Mid-line profile value: the mean front height over a narrow band of s.
static float profile(const hmap *m, float s, float u, float half)
{
    float sum = 0;
    int n = 0;
    for (int k = -2; k <= 2; k++) {
        float v = hm_at(m, s + half * k / 2.0f, u);
        if (v != -INFINITY) sum += v, n++;
    }
    return n ? sum / n : -INFINITY;
}

// Depth of a horizontal crease at (s, u): how much lower the surface is than both neighbours at +-d
// along up (positive inside a crease such as the lip line).
static float crease(const hmap *m, float s, float u, float d)
{
    float c = hm_at(m, s, u), a = hm_at(m, s, u + d), b = hm_at(m, s, u - d);
    if (c == -INFINITY || a == -INFINITY || b == -INFINITY) return -INFINITY;
    return fminf(a - c, b - c);
}

static void to_model(const rs_pack_face *f, float s, float u, float fw, float out[3])
{
    for (int a = 0; a < 3; a++) out[a] = s * f->side[a] + u * f->up[a] + fw * f->forward[a];
}

static float clamp01(float x)
{
    return x < 0 ? 0 : x > 1 ? 1 : x;
}

// The evidence that the landmarks found lie on a face (each term in [0, 1]); written to f->evidence and
// f->confidence. Anything with a bump reaches the landmark search (a spider's abdomen, a pig's tail, an
// engine's bolt), so each term asks what a face has and most other bumps lack:
//   symmetry: the front surface within +-0.3 H of the nose mirrors about the mid-line (both sides filled,
//             depths within 2% H): faces 60..95 % of the pairs, parts and animals seen from their end less;
//   nose:     the tip stands 1.2..4.5% H in front of a ring around it (faces 0.9..3.4 %; a snout, a bolt more);
//   eyes:     two hollows, one each side 0.07..0.21 H from the mid-line and 0.04..0.24 H above the tip,
//             mirrored (within 5% H), 4..35% H below the ring around them (faces 10..36 %, gaps between parts
//             deeper);
//   mouth:    a horizontal crease on the mid-line where the mouth was put, shallow (faces 0.04..0.2% H).
// The ranges were read off the Lee Perry-Smith and Demosthenes scans and assimp's test models.
static void face_evidence(const hmap *m, rs_pack_face *f, float nose_s, float nose_u, float H, float nose_p,
                          float mouth_u)
{
    int agree = 0, seen = 0;
    for (int j = -12; j <= 12; j++)
        for (int i = 1; i <= 12; i++) {
            float u = nose_u + 0.025f * H * j, ds = 0.025f * H * i;
            float a = hm_at(m, nose_s - ds, u), b = hm_at(m, nose_s + ds, u);
            if (a == -INFINITY && b == -INFINITY) continue;
            seen++;
            agree += a != -INFINITY && b != -INFINITY && fabsf(a - b) < 0.02f * H;
        }
    float sym = seen ? (float)agree / seen : 0;
    f->evidence[0] = clamp01((sym - 0.4f) / 0.4f);
    float p = nose_p / H;
    f->evidence[1] = fminf(clamp01((p - 0.005f) / 0.007f), clamp01((0.08f - p) / 0.035f));
    float eye_d[2] = {0, 0}, eye_s[2] = {0, 0}, eye_u[2] = {0, 0};
    for (int side = 0; side < 2; side++) {
        float dir = side ? 1.0f : -1.0f;
        for (int j = 0; j <= 10; j++)
            for (int i = 0; i <= 7; i++) {
                float s = nose_s + dir * (0.07f + 0.02f * i) * H, u = nose_u + (0.04f + 0.02f * j) * H;
                float d = -protrusion(m, s, u, 0.06f * H, -INFINITY);
                if (d != INFINITY && d > eye_d[side]) eye_d[side] = d, eye_s[side] = s, eye_u[side] = u;
            }
    }
    bool mirrored = fabsf(eye_s[0] + eye_s[1] - 2 * nose_s) < 0.05f * H && fabsf(eye_u[0] - eye_u[1]) < 0.05f * H;
    // Deeper than half a face height is a hole or a gap between parts, not an eye socket.
    float e_lo = fminf(eye_d[0], eye_d[1]) / H, e_hi = fmaxf(eye_d[0], eye_d[1]) / H;
    f->evidence[2] = fminf(clamp01((e_lo - 0.01f) / 0.03f), clamp01((0.5f - e_hi) / 0.15f)) * (mirrored ? 1.0f : 0.25f);
    float c = crease(m, nose_s, mouth_u, 0.012f * H) / H;
    f->evidence[3] = c == -INFINITY ? 0 : fminf(clamp01(c / 0.0004f), clamp01((0.04f - c) / 0.02f));
    f->confidence = 0.25f * (f->evidence[0] + f->evidence[1] + f->evidence[2] + f->evidence[3]);
}

// Everything past the frame: returns false when no face can be read (then the caller keeps defaults).
// H_fixed > 0 sets the face height instead of measuring it from the top of the scan (a face-only scan).
static bool find_landmarks(const float (*pos)[3], const float (*normal)[3], uint32_t count, rs_pack_face *f, hmap *m,
                           float *tmp, float H_fixed)
{
    // Silhouette rows: width of the filled cells per row, top down.
    int top_row = -1;
    for (int y = m->h - 1; y >= 0 && top_row < 0; y--)
        for (int x = 0; x < m->w; x++)
            if (hm_get(m, x, y) != -INFINITY) {
                top_row = y;
                break;
            }
    if (top_row < 0) return false;
    float *width = tmp, *mid = tmp + m->h;
    for (int y = 0; y < m->h; y++) {
        int lo = -1, hi = -1;
        for (int x = 0; x < m->w; x++)
            if (hm_get(m, x, y) != -INFINITY) {
                if (lo < 0) lo = x;
                hi = x;
            }
        width[y] = lo < 0 ? 0 : (float)(hi - lo + 1) * m->cell;
        mid[y] = lo < 0 ? 0 : m->s0 + (lo + hi + 1) * 0.5f * m->cell;
    }
    // The head: from the top down to the first clear narrowing (neck or chin) below its widest row;
    // shoulders widen again after it. Without one (a face-only scan), the whole height.
    float run_max = 0;
    int neck = 0, widest = top_row;
    for (int y = top_row; y >= 0; y--) {
        if (width[y] > run_max) {
            run_max = width[y];
            widest = y;
        }
        if (width[y] < 0.8f * run_max) {
            int best = y;
            for (int z = y; z >= 0 && width[z] <= run_max; z--)
                if (width[z] < width[best]) best = z;
            neck = best;
            break;
        }
    }
    // The vertex from the points themselves: the map's cells are padded by the splat footprint.
    float top_u = -INFINITY;
    for (uint32_t i = 0; i < count; i++) top_u = fmaxf(top_u, dot3(pos[i], f->up));
    float neck_u = m->u0 + neck * m->cell;
    float h0 = top_u - neck_u, head_w = width[widest];
    if (!(h0 > 0) || !(head_w > 0)) return false;
    // Head mid-line: the centre of the widest row (the skull is symmetric there).
    float s_mid = mid[widest];

    // Nose tip: the most protruding cell of the upper-middle face.
    float rho = 0.06f * h0, best_p = -INFINITY, nose_s = 0, nose_u = 0;
    for (int y = hm_y(m, top_u - 1.0f * h0); y <= hm_y(m, top_u - 0.3f * h0); y++)
        for (int x = hm_x(m, s_mid - 0.2f * head_w); x <= hm_x(m, s_mid + 0.2f * head_w); x++) {
            float s = m->s0 + (x + 0.5f) * m->cell, u = m->u0 + (y + 0.5f) * m->cell;
            float p = protrusion(m, s, u, rho, best_p);
            if (p > best_p) {
                best_p = p;
                nose_s = s;
                nose_u = u;
            }
        }
    if (!(best_p > 0.01f * h0)) return false;  // nothing sticks out: not a face seen from the front
    // The scan point nearest the tip's line of sight, most forward within one cell.
    float nose_f = -INFINITY;
    uint32_t tip = 0;
    for (uint32_t i = 0; i < count; i++) {
        float s = dot3(pos[i], f->side), u = dot3(pos[i], f->up);
        if (fabsf(s - nose_s) > 2 * m->cell || fabsf(u - nose_u) > 2 * m->cell) continue;
        float fw = dot3(pos[i], f->forward);
        if (fw > nose_f) {
            nose_f = fw;
            tip = i;
        }
    }
    if (nose_f == -INFINITY) return false;
    memcpy(f->nose_tip, pos[tip], sizeof f->nose_tip);
    nose_s = dot3(pos[tip], f->side);
    nose_u = dot3(pos[tip], f->up);

    float H = H_fixed > 0 ? H_fixed : (top_u - nose_u) / VERTEX_TO_NOSE;
    if (!(H > 0.05f * h0) || !isfinite(H)) return false;  // a nose at the very top is no face
    f->face_height = H;
    // Is the top of the scan the crown? On a whole head the highest points face up; a face-only scan
    // ends in a cut across the forehead, whose points face forward.
    if (normal) {
        double up_sum = 0;
        uint32_t up_n = 0;
        for (uint32_t i = 0; i < count; i++)
            if (dot3(pos[i], f->up) > top_u - 0.03f * H) up_sum += dot3(normal[i], f->up), up_n++;
        f->crown = up_n && up_sum / up_n > 0.6;
    } else {
        f->crown = true;
    }
    // Without the crown the vertex is where it would be: VERTEX_TO_NOSE H above the nose tip.
    if (H_fixed > 0) top_u = fmaxf(top_u, nose_u + VERTEX_TO_NOSE * H);
    to_model(f, nose_s, top_u, hm_at(m, nose_s, top_u - m->cell), f->top);

    // Mid-line profile landmarks.
    float band = 0.012f * H, step = m->cell * 0.5f;
    // Going up the mid-line profile from the tip: the nasion is the first dip, the glabella (brow) the
    // bump after it (extrema over +-1% H; the forehead recedes above, so a plain minimum over a window
    // would land on the forehead). Defaults: the bundled head's 0.16 H and 0.225 H.
    enum { PROFILE_N = 61 };
    float prof[PROFILE_N];
    float nasion_u = nose_u + 0.16f * H, glabella_u = nose_u + 0.225f * H;
    for (int i = 0; i < PROFILE_N; i++) prof[i] = profile(m, nose_s, nose_u + 0.005f * H * i, band);
    for (int i = 12, stage = 0; i + 2 < PROFILE_N && stage < 2; i++) {
        if (prof[i - 2] == -INFINITY || prof[i - 1] == -INFINITY || prof[i] == -INFINITY ||
            prof[i + 1] == -INFINITY || prof[i + 2] == -INFINITY)
            continue;
        float v = prof[i];
        if (stage == 0 && v <= prof[i - 1] && v <= prof[i - 2] && v < prof[i + 1] && v < prof[i + 2]) {
            nasion_u = nose_u + 0.005f * H * i;
            stage = 1;
        } else if (stage == 1 && v >= prof[i - 1] && v >= prof[i - 2] && v > prof[i + 1] && v > prof[i + 2]) {
            glabella_u = nose_u + 0.005f * H * i;
            stage = 2;
        }
    }
    if (glabella_u <= nasion_u) glabella_u = nasion_u + 0.06f * H;
    f->brow_y = glabella_u - nose_u;

    // Stomion: going down the mid-line profile from the tip, the subnasale is the first dip, the upper
    // lip the next bump, and the lip line the dip after it (extrema over +-1% H). When the profile does
    // not show that order (a moustache, a sparse cloud), take the lip-line crease nearest 0.145 H below
    // the tip, the bundled head's ratio.
    for (int i = 0; i < PROFILE_N; i++) prof[i] = profile(m, nose_s, nose_u - 0.005f * H * i, band);
    int want_min = 1, found = 0, stage = 0;
    float mouth_u = nose_u - 0.145f * H, d = 0.012f * H;
    for (int i = 6; i + 2 < PROFILE_N && stage < 3; i++) {
        float v = prof[i];
        if (v == -INFINITY || prof[i - 1] == -INFINITY || prof[i - 2] == -INFINITY || prof[i + 1] == -INFINITY ||
            prof[i + 2] == -INFINITY)
            continue;
        bool is_min = v <= prof[i - 1] && v <= prof[i - 2] && v < prof[i + 1] && v < prof[i + 2];
        bool is_max = v >= prof[i - 1] && v >= prof[i - 2] && v > prof[i + 1] && v > prof[i + 2];
        if ((want_min && is_min) || (!want_min && is_max)) {
            stage++;
            want_min = !want_min;
            if (stage == 3 && i * 0.005f <= 0.22f) {
                mouth_u = nose_u - 0.005f * H * i;
                found = 1;
            }
        }
    }
    // Loops step by index, never by adding to a float: far from the origin a small step could round
    // away and never end the loop.
    if (!found) {
        float want = mouth_u, best = INFINITY;
        for (int i = 20; i <= 38; i++) {
            float u = nose_u - 0.005f * H * i;
            float c = crease(m, nose_s, u, d);
            if (!(c > 0.0005f * H)) continue;
            float score = fabsf(u - want) / H - 0.5f * c / H;
            if (score < best) best = score, mouth_u = u;
        }
    }
    // Walk to the bottom of that crease.
    for (int it = 0; it < 8; it++) {
        float up = hm_at(m, nose_s, mouth_u + step), dn = hm_at(m, nose_s, mouth_u - step), c = hm_at(m, nose_s, mouth_u);
        if (up < c && up <= dn) mouth_u += step;
        else if (dn < c) mouth_u -= step;
        else break;
    }
    to_model(f, nose_s, mouth_u, hm_at(m, nose_s, mouth_u), f->mouth);

    // Mouth corners: follow the crease sideways, letting it drift by half a cell per step at most
    // (the lip line bends down a little toward the corners), until it is weaker than 40% of its
    // strength near the mid-line: the crease fades out at the corners.
    for (int side = 0; side < 2; side++) {
        float dir = side ? 1.0f : -1.0f, u = mouth_u, last_s = nose_s, last_u = mouth_u, ref = 0;
        int nref = 0, steps = (int)RS_MIN(0.16f * H / m->cell, 4096.0f);
        for (int k = 0; k < steps; k++) {
            float s = nose_s + dir * m->cell * k, bu = u, bc = -INFINITY;
            for (int j = -1; j <= 1; j++) {
                float c = crease(m, s, u + j * m->cell * 0.5f, d);
                if (c > bc + 1e-6f * H) bc = c, bu = u + j * m->cell * 0.5f;
            }
            // Reference strength: the mean over the central 3% H.
            if (k * m->cell < 0.03f * H) {
                if (bc > -INFINITY) ref += bc, nref++;
                continue;
            }
            if (!(nref > 0 && ref > 0) || bc < 0.4f * ref / nref) break;
            u = bu;
            last_s = s;
            last_u = u;
        }
        // No lip crease to follow (a beard, a closed smooth mouth): the typical half-width, 9% H.
        if (!(ref > 0) || fabsf(last_s - nose_s) < 0.05f * H) {
            last_s = nose_s + dir * 0.09f * H;
            last_u = mouth_u;
        }
        to_model(f, last_s, last_u, hm_at(m, last_s, last_u), f->mouth_corner[side]);
    }

    // Pogonion: the chin's most forward point below the mouth.
    float chin_u = mouth_u - 0.12f * H;
    float high = -INFINITY;
    for (int i = 10; i <= 40; i++) {
        float u = mouth_u - 0.005f * H * i;
        float v = profile(m, nose_s, u, band);
        if (v != -INFINITY && v > high) high = v, chin_u = u;
    }
    to_model(f, nose_s, chin_u, hm_at(m, nose_s, chin_u), f->chin);

    // Face width: the silhouette row at the nose tip.
    int ny = hm_y(m, nose_u);
    f->face_width = ny >= 0 && ny < m->h ? width[ny] : head_w;

    // Orbit centre: on the mirror plane through the nose tip, half a face height below the top, and
    // midway between the face and the back of the head at that height.
    float cu = top_u - 0.5f * H, back = INFINITY, front = -INFINITY;
    for (uint32_t i = 0; i < count; i++) {
        float u = dot3(pos[i], f->up), s = dot3(pos[i], f->side);
        if (fabsf(u - cu) > 0.05f * H || fabsf(s - nose_s) > 0.1f * H) continue;
        float fw = dot3(pos[i], f->forward);
        back = fminf(back, fw);
        front = fmaxf(front, fw);
    }
    if (back == INFINITY) back = front = nose_f;
    to_model(f, nose_s, cu, 0.5f * (front + back), f->centre);
    face_evidence(m, f, nose_s, nose_u, H, best_p, mouth_u);
    return true;
}

// The centre and size of a model without a face: its bounding box's centre and diagonal (the camera's
// zoom 1 fits the whole model from any side).
static void bounds_frame(const float (*pos)[3], uint32_t count, rs_pack_face *f)
{
    float mn[3] = {INFINITY, INFINITY, INFINITY}, mx[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = 0; i < count; i++)
        for (int a = 0; a < 3; a++) mn[a] = fminf(mn[a], pos[i][a]), mx[a] = fmaxf(mx[a], pos[i][a]);
    for (int a = 0; a < 3; a++) f->centre[a] = 0.5f * (mn[a] + mx[a]);
    f->face_height = (float)hypot(hypot((double)mx[0] - mn[0], (double)mx[1] - mn[1]), (double)mx[2] - mn[2]);
    if (!(f->face_height > 0) || !isfinite(f->face_height)) f->face_height = 1.0f;
}

// The frame of a model without a face and without axes given: +y up and +z forward (the convention of
// glTF, OBJ and most exporters), except that a flat model (one bounding-box side under a third of the
// next) is seen face-on, along its thin axis, and a model whose z side is over 3x the others while y is
// the shortest (a standing figure from a z-up exporter; a y-up car, 2.5x, is not one) stands on z.
static void plain_axes(const float (*pos)[3], uint32_t count, rs_pack_face *f)
{
    float mn[3] = {INFINITY, INFINITY, INFINITY}, mx[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = 0; i < count; i++)
        for (int a = 0; a < 3; a++) mn[a] = fminf(mn[a], pos[i][a]), mx[a] = fmaxf(mx[a], pos[i][a]);
    float e[3];
    for (int a = 0; a < 3; a++) e[a] = mx[a] - mn[a];
    if (!isfinite(e[0] + e[1] + e[2])) return;
    int thin = 0;
    for (int a = 1; a < 3; a++)
        if (e[a] < e[thin]) thin = a;
    float mid = fminf(e[(thin + 1) % 3], e[(thin + 2) % 3]);
    float up[3] = {0, 1, 0}, fw[3] = {0, 0, 1};
    if (e[thin] < mid / 3) {
        if (thin == 0) fw[2] = 0, fw[0] = 1;                      // a wall in yz: from +x
        else if (thin == 1) up[1] = 0, up[2] = -1, fw[2] = 0, fw[1] = 1;  // lying in xz: from above, +z down
    } else if (e[2] > 3.0f * fmaxf(e[0], e[1]) && e[1] <= e[0]) {
        up[1] = 0, up[2] = 1, fw[2] = 0, fw[1] = -1;  // z up, looking along -y (Blender's front view)
    }
    memcpy(f->up, up, sizeof up);
    memcpy(f->forward, fw, sizeof fw);
    f->side[0] = up[1] * fw[2] - up[2] * fw[1];
    f->side[1] = up[2] * fw[0] - up[0] * fw[2];
    f->side[2] = up[0] * fw[1] - up[1] * fw[0];
}

rs_result rs_pack_find_face(const float (*pos)[3], const float (*normal)[3], uint32_t count,
                            rs_pack_axis up, rs_pack_axis forward, rs_pack_face *out, rs_error *err)
{
    float u[3], fw[3];
    axis_vector(up, RS_PACK_AXIS_POS_Y, u);
    axis_vector(forward, RS_PACK_AXIS_POS_Z, fw);
    if (fabsf(dot3(u, fw)) > 0.5f) return rs_fail(err, RS_ERR_ARG, "--up and --forward must be different axes");
    bool guess = up == RS_PACK_AXIS_DEFAULT && forward == RS_PACK_AXIS_DEFAULT;
    float best = 0, best_ev[4] = {0, 0, 0, 0};
    if (guess) {
        // No axes given: the frame comes from the scan itself, whatever its orientation (pack_frame.c);
        // when no face can be read that way, the default axes frame the model.
        bool found;
        float ou[3], of[3], mid;
        rs_result r = rs_pack_orient(pos, normal, count, ou, of, &mid, &found, err);
        if (r != RS_OK) return r;
        if (found) {
            r = rs_pack_find_face_frame(pos, normal, count, ou, of, out, err);
            if (r != RS_OK) return r;
            if (out->found && out->confidence >= RS_PACK_FACE_MIN_CONFIDENCE) {
                // The orbit centre on the mirror plane, which the whole scan fixes better than the one
                // nose-tip point the finder puts it through.
                float off = dot3(out->centre, out->side) - mid;
                for (int a = 0; a < 3; a++) out->centre[a] -= off * out->side[a];
                return RS_OK;
            }
            if (out->found && isfinite(out->confidence)) best = out->confidence, memcpy(best_ev, out->evidence, sizeof best_ev);
        }
    }
    rs_result r = rs_pack_find_face_frame(pos, normal, count, u, fw, out, err);
    if (r != RS_OK) return r;
    if (out->found && out->confidence >= RS_PACK_FACE_MIN_CONFIDENCE) return RS_OK;
    if (out->found && isfinite(out->confidence) && out->confidence > best)
        best = out->confidence, memcpy(best_ev, out->evidence, sizeof best_ev);
    // Too little of a face: the plain frame (the bounds; without axes given, plain_axes's); the best
    // candidate's evidence stays for the report.
    if (guess) {
        rs_pack_face axes = {0};
        plain_axes(pos, count, &axes);
        memcpy(u, axes.up, sizeof u);
        memcpy(fw, axes.forward, sizeof fw);
    }
    r = rs_pack_find_face_frame(pos, normal, 0, u, fw, out, err);
    if (r != RS_OK) return r;
    bounds_frame(pos, count, out);
    out->confidence = best;
    memcpy(out->evidence, best_ev, sizeof best_ev);
    return RS_OK;
}

rs_result rs_pack_find_face_frame(const float (*pos)[3], const float (*normal)[3], uint32_t count, const float up[3],
                                  const float forward[3], rs_pack_face *out, rs_error *err)
{
    rs_pack_face f = {0};
    memcpy(f.up, up, sizeof f.up);
    memcpy(f.forward, forward, sizeof f.forward);
    f.side[0] = f.up[1] * f.forward[2] - f.up[2] * f.forward[1];
    f.side[1] = f.up[2] * f.forward[0] - f.up[0] * f.forward[2];
    f.side[2] = f.up[0] * f.forward[1] - f.up[1] * f.forward[0];

    // Defaults for a scan that is not a readable face: the bounding box.
    float mn[3] = {INFINITY, INFINITY, INFINITY}, mx[3] = {-INFINITY, -INFINITY, -INFINITY};
    float lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    uint32_t frontish = 0;
    for (uint32_t i = 0; i < count; i++) {
        for (int a = 0; a < 3; a++) {
            mn[a] = fminf(mn[a], pos[i][a]);
            mx[a] = fmaxf(mx[a], pos[i][a]);
        }
        float s = dot3(pos[i], f.side), u = dot3(pos[i], f.up);
        lo[0] = fminf(lo[0], s);
        hi[0] = fmaxf(hi[0], s);
        lo[1] = fminf(lo[1], u);
        hi[1] = fmaxf(hi[1], u);
        frontish += normal && dot3(normal[i], f.forward) > 0.3f;
    }
    // Not a face: the whole model is framed, so its bounding sphere's diameter stands in for the face
    // height (the camera's zoom 1 fits it from any side). A face found below replaces both.
    for (int a = 0; a < 3; a++) f.centre[a] = 0.5f * (mn[a] + mx[a]);
    f.face_height = (float)hypot(hypot((double)mx[0] - mn[0], (double)mx[1] - mn[1]), (double)mx[2] - mn[2]);
    if (!(f.face_height > 0) || !isfinite(f.face_height)) f.face_height = 1.0f;
    if (count < 100) {  // too few points to read a face from
        *out = f;
        return RS_OK;
    }

    // Height map cells: fine enough for lips (~1/300 of the scan), coarse enough that the points
    // cover it: the front-facing points spread over the silhouette area set the spacing.
    float ext = fmaxf(hi[0] - lo[0], hi[1] - lo[1]);
    if (!(ext > 0) || !isfinite(ext)) {
        *out = f;
        return RS_OK;
    }
    hmap m = {.cell = ext / 64.0f};
    for (int k = 0; k < 16; k++) {
        float a = (float)k * 0.39269908f;  // 2 pi / 16
        m.ring[k][0] = cosf(a), m.ring[k][1] = sinf(a);
    }
    m.s0 = lo[0] - 2 * m.cell;
    m.u0 = lo[1] - 2 * m.cell;
    m.w = (int)((hi[0] - lo[0]) / m.cell) + 5;
    m.h = (int)((hi[1] - lo[1]) / m.cell) + 5;
    uint8_t *occ = calloc((size_t)m.w * m.h, 1);
    if (!occ) return rs_fail(err, RS_ERR_NOMEM, "face: out of memory");
    uint32_t occupied = 0;
    for (uint32_t i = 0; i < count; i++) {
        int x = hm_x(&m, dot3(pos[i], f.side)), y = hm_y(&m, dot3(pos[i], f.up));
        uint8_t *o = &occ[(size_t)y * m.w + x];
        occupied += !*o;
        *o = 1;
    }
    free(occ);
    float spacing = (float)sqrt((double)occupied * m.cell * m.cell / (double)(frontish ? frontish : count));
    if (!isfinite(spacing)) {
        *out = f;
        return RS_OK;
    }
    m.cell = fmaxf(ext / 400.0f, 0.75f * spacing);
    m.s0 = lo[0] - 2 * m.cell;
    m.u0 = lo[1] - 2 * m.cell;
    m.w = (int)((hi[0] - lo[0]) / m.cell) + 5;
    m.h = (int)((hi[1] - lo[1]) / m.cell) + 5;
    size_t cells = (size_t)m.w * m.h;
    m.f = rs_alloc_array(cells, sizeof *m.f);
    float *tmp = rs_alloc_array(cells > 2 * (size_t)m.h ? cells : 2 * (size_t)m.h, sizeof *tmp);
    if (!m.f || !tmp) {
        free(m.f);
        free(tmp);
        return rs_fail(err, RS_ERR_NOMEM, "face: out of memory for a %dx%d height map", m.w, m.h);
    }
    for (size_t c = 0; c < cells; c++) m.f[c] = -INFINITY;
    // Each point covers a disk of about the spacing, so the map has no holes where the surface faces
    // the viewer; points facing away never show from the front and are left out.
    int r = (int)RS_MIN(ceilf(1.5f * spacing / m.cell), 2.0f);  // cell >= 0.75 spacing: at most 2
    float r2 = (1.5f * spacing / m.cell) * (1.5f * spacing / m.cell);
    for (uint32_t i = 0; i < count; i++) {
        if (normal && dot3(normal[i], f.forward) < -0.2f) continue;
        float x = (dot3(pos[i], f.side) - m.s0) / m.cell, y = (dot3(pos[i], f.up) - m.u0) / m.cell;
        float fw = dot3(pos[i], f.forward);
        for (int yy = (int)floorf(y) - r; yy <= (int)floorf(y) + r; yy++)
            for (int xx = (int)floorf(x) - r; xx <= (int)floorf(x) + r; xx++) {
                float dx = xx + 0.5f - x, dy = yy + 0.5f - y;
                if (xx < 0 || yy < 0 || xx >= m.w || yy >= m.h || dx * dx + dy * dy > r2) continue;
                float *c = &m.f[(size_t)yy * m.w + xx];
                *c = fmaxf(*c, fw);
            }
    }
    hm_fill(&m, 1, tmp);
    hm_blur(&m, 1, tmp);
    rs_pack_face g = f;
    if (find_landmarks(pos, normal, count, &g, &m, tmp, 0)) {
        g.found = true;
        f = g;
        // A face-only scan: the top is not the vertex, so the height measured from it is short. The lip
        // line lies 0.142 H below the nose tip along up (the bundled head in its facial frame; adult
        // norms, pronasale to stomion ~32-36 mm of ~225): H is the scale at which the landmarks found
        // put the lips there. The mouth search itself scales with H, so iterate from 1.3 x the
        // top-based height (a cut at the hairline loses ~0.25 H) until H settles.
        float H = 1.3f * g.face_height;
        for (int it = 0; !f.crown && it < 6; it++) {
            rs_pack_face t = f;
            if (!find_landmarks(pos, normal, count, &t, &m, tmp, H)) break;
            float H_mouth = (dot3(t.nose_tip, t.up) - dot3(t.mouth, t.up)) / 0.142f;
            t.found = true;
            t.crown = false;
            g = t;
            if (!(H_mouth > 0) || !isfinite(H_mouth) || fabsf(H_mouth - H) < 0.01f * H) break;
            H = fmaxf(H_mouth, f.face_height);
        }
        if (!f.crown) f = g;
    }
    free(m.f);
    free(tmp);
    *out = f;
    return RS_OK;
}
