// test_shadow.c — the shadow map's bias (issue 12): on a synthetic scene in millimetres (a floor, and a
// thin wall standing on it, lit from the side at 30, 45 and 60 degrees), the cast shadow's edge lies where
// geometry puts it, x = -h tan(theta), within 0.3 mm; and lit surfaces do not shadow themselves (no acne)
// on the floor and on a sphere lit at every angle up to near grazing.
#include "support/harness.h"
#include "render/render_internal.h"  // RS_COVERAGE: how far the disks reach

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#define SIZE 512
#define WALL_H 20.0f    // mm: the top row of wall splats sits here
#define RADIUS 0.3f     // mm
#define SPACING 0.4f    // mm between splats

static rs_gl_context *gl;

// A floor z = 0 over x, y in [-40, 40] (normal +z) and a wall x = 0, z in [0, WALL_H] (normal +x, towards
// the light), in millimetres; optionally a sphere instead.
static rs_splat_cloud *make_scene(bool sphere)
{
    size_t cap = 500000, n = 0;
    rs_splat *s = calloc(cap, sizeof *s);
    if (!s) return NULL;
    if (sphere) {
        // A sphere of radius 20 mm: Fibonacci points at about SPACING apart.
        int k = (int)(4.0f * 3.14159f * 400.0f / (SPACING * SPACING));
        for (int i = 0; i < k && n < cap; i++) {
            float z = 1.0f - (2.0f * i + 1.0f) / k, r = sqrtf(1.0f - z * z), phi = 2.39996323f * i;
            float d[3] = {r * cosf(phi), r * sinf(phi), z};
            rs_splat *p = &s[n++];
            for (int a = 0; a < 3; a++) p->pos[a] = 20.0f * d[a], p->normal[a] = d[a];
            p->radius = RADIUS;
            p->rgb[0] = p->rgb[1] = p->rgb[2] = 200;
        }
    } else {
        for (float y = -40; y <= 40; y += SPACING)
            for (float x = -40; x <= 40; x += SPACING) {
                rs_splat *p = &s[n++];
                p->pos[0] = x, p->pos[1] = y, p->normal[2] = 1;
                p->radius = RADIUS;
                p->rgb[0] = p->rgb[1] = p->rgb[2] = 200;
            }
        for (float y = -40; y <= 40; y += SPACING)
            for (int k = 1; k <= (int)lroundf(WALL_H / SPACING); k++) {
                float z = WALL_H * (float)k / lroundf(WALL_H / SPACING);
                rs_splat *p = &s[n++];
                p->pos[1] = y, p->pos[2] = z, p->normal[0] = 1;
                p->radius = RADIUS;
                p->rgb[0] = p->rgb[1] = p->rgb[2] = 200;
            }
    }
    rs_splat_header h = {.mm_per_unit = 1.0f, .forward = {0, 0, 1}, .up = {0, 1, 0}, .face_height = 60.0f};
    rs_splat_cloud *c = NULL;
    rs_error err = {0};
    if (rs_splat_create(s, (uint32_t)n, &h, &c, &err) != RS_OK) printf("# scene: %s\n", err.msg);
    free(s);
    return c;
}

// The light's visibility along the image row through y = 0, sub-pixel: where it crosses 0.5, in mm.
static bool shadow_edge_mm(rs_renderer *r, const rs_view *v, const rs_image *img, float *edge_mm)
{
    float a[3] = {-30, 0, 0}, b[3] = {0, 0, 0}, pa[2], pb[2];
    if (!rs_render_project(r, v, a, pa) || !rs_render_project(r, v, b, pb)) return false;
    float px_per_mm = (pb[0] - pa[0]) / 30.0f;
    int row = (int)lroundf(pb[1]);
    // From the wall outwards (x < 0): the first crossing from dark to lit.
    for (int x = (int)pb[0] - 3; x > 1; x--) {
        int v0 = img->pixels[((size_t)row * img->width + x) * 4];
        int v1 = img->pixels[((size_t)row * img->width + x - 1) * 4];
        if (v0 < 128 && v1 >= 128) {
            float t = (128.0f - v0) / (float)(v1 - v0);
            *edge_mm = ((float)x - t + 0.5f - pb[0]) / px_per_mm;
            return true;
        }
    }
    return false;
}

static void test_cast_shadow_edges_lie_where_geometry_puts_them(void)
{
    rs_splat_cloud *c = make_scene(false);
    RS_REQUIRE(c, "scene");
    rs_renderer *r = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_render_create(&(rs_render_desc){.cloud = c, .caps = rs_gl_get_caps(gl)}, &r, &err) == RS_OK, "%s",
               err.msg);
    const float angles[] = {30, 45, 60};
    for (size_t i = 0; i < RS_COUNT_OF(angles); i++) {
        rs_view v = rs_view_defaults();
        v.width = v.height = SIZE;
        v.mode = RS_MODE_SHADOW;
        v.zoom = 1.2f;
        v.pan[0] = 0.2f;
        // Light from +x, theta from the floor's normal (the wall faces it).
        v.key.yaw_deg = angles[i], v.key.pitch_deg = 0;
        rs_image img = {0};
        if (!RS_CHECK(rs_render_image(r, &v, &img, &err) == RS_OK, "%s", err.msg)) break;
        // The wall's top: its top row of disks, which are drawn out to RS_COVERAGE radii.
        float top = WALL_H + RS_COVERAGE * RADIUS;
        float edge = 0, want = -top * tanf(angles[i] * 3.14159265f / 180.0f);
        bool found = shadow_edge_mm(r, &v, &img, &edge);
        printf("# light at %.0f deg: shadow edge at %.3f mm, geometry %.3f mm (%+.3f)\n", angles[i], edge, want,
               edge - want);
        if (!RS_CHECK(found && fabsf(edge - want) < 0.3f, "%.0f deg: edge %.3f mm, want %.3f (off by %.3f)", angles[i],
                      edge, want, edge - want)) {
            char name[64];
            snprintf(name, sizeof name, "shadow_edge_%.0f", angles[i]);
            rs_test_save(name, &img);
        }
        // No acne on the lit floor beyond the wall (2 to 38 mm on the light's side).
        float o[3] = {0, 0, 0}, a[3] = {-30, 0, 0}, q0[2], qa[2];
        int bad = 0, n = 0;
        if (rs_render_project(r, &v, o, q0) && rs_render_project(r, &v, a, qa)) {
            float px_per_mm = (q0[0] - qa[0]) / 30.0f;
            for (int y = SIZE / 4; y < 3 * SIZE / 4; y++)
                for (int x = 0; x < SIZE; x++) {
                    float mm = ((float)x + 0.5f - q0[0]) / px_per_mm;
                    if (mm < 2.0f || mm > 38.0f) continue;
                    n++;
                    bad += img.pixels[((size_t)y * SIZE + x) * 4] < 252;
                }
        }
        RS_CHECK(n > 1000 && bad == 0, "%.0f deg: %d of %d lit floor pixels below 0.99 visibility (acne)", angles[i],
                 bad, n);
        rs_image_free(&img);
    }
    rs_render_destroy(r);
    rs_splat_destroy(c);
}

// A sphere lit from the side: wherever N.L > 0.25 (up to ~75 degrees from the light) it is fully lit.
static void test_no_acne_on_a_lit_sphere(void)
{
    rs_splat_cloud *c = make_scene(true);
    RS_REQUIRE(c, "scene");
    rs_renderer *r = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_render_create(&(rs_render_desc){.cloud = c, .caps = rs_gl_get_caps(gl)}, &r, &err) == RS_OK, "%s",
               err.msg);
    rs_view v = rs_view_defaults();
    v.width = v.height = 384;
    v.mode = RS_MODE_SHADOW;
    v.zoom = 2.0f;
    v.key.yaw_deg = 50, v.key.pitch_deg = 20;
    rs_image shadow = {0}, normals = {0};
    bool ok = RS_CHECK(rs_render_image(r, &v, &shadow, &err) == RS_OK, "%s", err.msg);
    v.mode = RS_MODE_NORMALS;
    ok = ok && RS_CHECK(rs_render_image(r, &v, &normals, &err) == RS_OK, "%s", err.msg);
    if (ok) {
        // The light direction in view space: the camera looks along -z from +z (yaw 0, pitch 0).
        float y = 50 * 3.14159265f / 180, p = 20 * 3.14159265f / 180;
        float L[3] = {cosf(p) * sinf(y), sinf(p), cosf(p) * cosf(y)};
        int bad = 0, n = 0;
        for (size_t i = 0; i < (size_t)384 * 384; i++) {
            const uint8_t *q = normals.pixels + i * 4;
            // The top-left corner is background.
            if (q[0] == normals.pixels[0] && q[1] == normals.pixels[1] && q[2] == normals.pixels[2]) continue;
            float N[3] = {q[0] / 127.5f - 1, q[1] / 127.5f - 1, q[2] / 127.5f - 1};
            if (N[0] * L[0] + N[1] * L[1] + N[2] * L[2] < 0.25f) continue;
            n++;
            bad += shadow.pixels[i * 4] < 252;
        }
        printf("# sphere: %d of %d pixels with N.L > 0.25 below 0.99 visibility\n", bad, n);
        RS_CHECK(n > 5000 && bad <= n / 500, "sphere: %d of %d lit pixels show acne", bad, n);
        if (bad > n / 500) rs_test_save("shadow_sphere", &shadow);
    }
    rs_image_free(&shadow);
    rs_image_free(&normals);
    rs_render_destroy(r);
    rs_splat_destroy(c);
}

int main(int argc, char **argv)
{
    rs_test_init(argc, argv);
    rs_error err = {0};
    if (rs_gl_create(&(rs_gl_desc){0}, &gl, &err) != RS_OK) {
        printf("skip - shadow: no GLES 3 context (%s)\n", err.msg);
        return rs_test_finish();
    }
    RS_RUN(test_cast_shadow_edges_lie_where_geometry_puts_them);
    RS_RUN(test_no_acne_on_a_lit_sphere);
    rs_gl_destroy(gl);
    return rs_test_finish();
}
