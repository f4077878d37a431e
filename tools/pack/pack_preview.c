// pack_preview.c — a CPU orthographic splat rasteriser for checking conversions without GL (see pack.h).
#include "pack/pack.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

// Preview colours per region id (those of the renderer's `regions` view); other ids draw as `other`.
static const uint8_t region_rgb[RS_REGION_STANDARD_COUNT][3] = {
    [RS_REGION_OTHER] = {150, 150, 150}, [RS_REGION_CHEEK] = {230, 40, 40}, [RS_REGION_NOSE] = {40, 200, 40},
    [RS_REGION_FOREHEAD] = {50, 90, 240}, [RS_REGION_LIPS] = {240, 220, 30}, [RS_REGION_EYELID] = {180, 80, 215},
    [RS_REGION_BROW] = {50, 205, 215},
};

typedef struct view {
    float right[3], up[3], toward[3];  // toward: from the subject to the camera (depth grows toward it)
} view;

static float dot3(const float a[3], const float b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

// Draws the cloud into the w x h panel at (x0, 0) of img: splats as screen disks, nearest wins.
static void draw_panel(const rs_splat_cloud *c, const view *v, float scale, const float mid[2], bool regions,
                       rs_image *img, float *depth, int x0, int w)
{
    int h = img->height;
    for (uint32_t i = 0; i < c->hdr.count; i++) {
        rs_splat s;
        rs_splat_get(c, i, &s);
        float facing = dot3(s.normal, v->toward);
        if (facing <= 0) continue;  // back-facing: the renderer culls these too
        float sx = (dot3(s.pos, v->right) - mid[0]) * scale + w * 0.5f;
        float sy = h * 0.5f - (dot3(s.pos, v->up) - mid[1]) * scale;
        // Degenerate scans (spread over 1e20, scaled to 1e-38) give inf/NaN or huge screen positions: skip
        // what is not on the panel before any float-to-int conversion (which would be undefined), and cap
        // the disk so one splat's cost stays bounded (a preview disk wider than 1/8 panel shows nothing).
        float z = dot3(s.pos, v->toward), r = fminf(fmaxf(s.radius * scale, 0.71f), w / 8.0f);
        if (!(isfinite(sx) && isfinite(sy) && isfinite(z) && r > 0)) continue;
        if (sx + r < 0 || sx - r > w || sy + r < 0 || sy - r > h) continue;
        // Headlight shading so the shape reads; colours stay sRGB, this is a debugging view.
        float shade = 0.3f + 0.7f * facing;
        const uint8_t *base = regions ? region_rgb[s.region < RS_REGION_STANDARD_COUNT ? s.region : 0] : s.rgb;
        uint8_t col[3];
        for (int a = 0; a < 3; a++) col[a] = (uint8_t)lrintf(RS_MIN(255.0f, base[a] * shade));
        int xa = (int)floorf(sx - r), xb = (int)ceilf(sx + r), ya = (int)floorf(sy - r), yb = (int)ceilf(sy + r);
        for (int y = RS_MAX(ya, 0); y <= RS_MIN(yb, h - 1); y++)
            for (int x = RS_MAX(xa, 0); x <= RS_MIN(xb, w - 1); x++) {
                float dx = x + 0.5f - sx, dy = y + 0.5f - sy;
                if (dx * dx + dy * dy > r * r) continue;
                size_t at = (size_t)y * img->width + x0 + x;
                if (z <= depth[at]) continue;
                depth[at] = z;
                memcpy(img->pixels + at * 3, col, 3);
            }
    }
}

rs_result rs_pack_preview(const rs_splat_cloud *c, int panel_px, rs_image *out, rs_error *err)
{
    if (panel_px < 16 || panel_px > 4096) return rs_fail(err, RS_ERR_ARG, "preview: panel size %d is outside 16..4096", panel_px);
    const rs_splat_header *hd = &c->hdr;
    view front, side;
    memcpy(front.up, hd->up, sizeof front.up);
    memcpy(front.toward, hd->forward, sizeof front.toward);
    // cross(up, forward): the subject's left, which a camera facing the subject sees on its right.
    front.right[0] = hd->up[1] * hd->forward[2] - hd->up[2] * hd->forward[1];
    front.right[1] = hd->up[2] * hd->forward[0] - hd->up[0] * hd->forward[2];
    front.right[2] = hd->up[0] * hd->forward[1] - hd->up[1] * hd->forward[0];
    // From the subject's left: the face points to the image's left.
    memcpy(side.up, hd->up, sizeof side.up);
    memcpy(side.toward, front.right, sizeof side.toward);
    for (int a = 0; a < 3; a++) side.right[a] = -hd->forward[a];

    // One scale for all panels, fitted to the larger of the two views' extents.
    float lo[2][2] = {{INFINITY, INFINITY}, {INFINITY, INFINITY}}, hi[2][2] = {{-INFINITY, -INFINITY}, {-INFINITY, -INFINITY}};
    for (uint32_t i = 0; i < hd->count; i++) {
        const view *vs[2] = {&front, &side};
        for (int k = 0; k < 2; k++) {
            float p[2] = {dot3(c->pos[i], vs[k]->right), dot3(c->pos[i], vs[k]->up)};
            for (int a = 0; a < 2; a++) {
                lo[k][a] = fminf(lo[k][a], p[a]);
                hi[k][a] = fmaxf(hi[k][a], p[a]);
            }
        }
    }
    float ext = 1e-6f;
    for (int k = 0; k < 2; k++)
        for (int a = 0; a < 2; a++) ext = fmaxf(ext, hi[k][a] - lo[k][a]);
    float mid[2][2];
    for (int k = 0; k < 2; k++)
        for (int a = 0; a < 2; a++) mid[k][a] = 0.5f * (lo[k][a] + hi[k][a]);
    // Frame the head (face height around the orbit centre) when the scan is larger than that, e.g. a bust.
    float head = 1.3f * hd->face_height;
    if (head > 0 && head < ext) {
        ext = head;
        const view *vs[2] = {&front, &side};
        for (int k = 0; k < 2; k++) {
            mid[k][0] = dot3(hd->centre, vs[k]->right);
            mid[k][1] = dot3(hd->centre, vs[k]->up);
        }
    }
    float scale = panel_px * 0.94f / ext;

    rs_image img = {0};
    rs_result r = rs_image_create(panel_px * 3, panel_px, 3, &img, err);
    if (r != RS_OK) return r;
    float *depth = rs_alloc_array((size_t)panel_px * 3 * panel_px, sizeof *depth);
    if (!depth) {
        rs_image_free(&img);
        return rs_fail(err, RS_ERR_NOMEM, "preview: out of memory");
    }
    for (size_t i = 0; i < (size_t)panel_px * 3 * panel_px; i++) {
        depth[i] = -INFINITY;
        memset(img.pixels + i * 3, 40, 3);
    }
    draw_panel(c, &front, scale, mid[0], false, &img, depth, 0, panel_px);
    draw_panel(c, &front, scale, mid[0], true, &img, depth, panel_px, panel_px);
    draw_panel(c, &side, scale, mid[1], true, &img, depth, 2 * panel_px, panel_px);
    free(depth);
    *out = img;
    return RS_OK;
}
