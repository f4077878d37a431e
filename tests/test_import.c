// test_import.c — rouge-pack's import (tools/pack/import.h): models through assimp into the converter's
// mesh, texture pages, embedded images, vertex colours, declared units, and bad inputs.
#define _POSIX_C_SOURCE 200809L
#include "support/harness.h"
#include "pack/import.h"
#include "pack/pack.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define FX "tests/fixtures/import/"

static rs_splat_cloud *convert(const rs_import_scene *s, const rs_image *pages, uint32_t points, rs_pack_report *rep)
{
    rs_error err = {0};
    rs_pack_desc d = {.points = points, .pages = pages, .page_count = pages ? s->page_count : 0, .mm_per_unit = 1};
    rs_splat_cloud *c = NULL;
    if (rs_pack_convert(s->mesh, &d, &c, rep, &err) != RS_OK) {
        RS_CHECK(false, "convert: %s", err.msg);
        return NULL;
    }
    return c;
}

static void test_obj_two_pages_sample_each_face_from_its_page(void)
{
    rs_error err = {0};
    rs_import_scene *s = NULL;
    RS_REQUIRE(rs_import_load(FX "two_pages.obj", &s, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(s->format == RS_IMPORT_OBJ && s->declared_mm_per_unit == 0, "format %d, unit %g", s->format, s->declared_mm_per_unit);
    // assimp's OBJ reader puts its default material first; faces use the MTL's two.
    RS_CHECK(s->page_count == 3 && !s->pages[0].texture && s->pages[1].texture && !strcmp(s->pages[1].texture, "page one.png") &&
                 !strcmp(s->pages[1].name, "left") && s->pages[2].texture && !strcmp(s->pages[2].texture, "page_two.png"),
             "pages: %u", s->page_count);
    // Four corners per square once OBJ's per-corner vertices are welded (the squares are separate
    // materials, so they keep their own vertices along the shared edge).
    RS_CHECK(s->mesh->vertex_count == 8 && s->mesh->tri_count == 4 && s->mesh->tri_page, "%u vertices, %u triangles",
             s->mesh->vertex_count, s->mesh->tri_count);
    RS_CHECK(strstr(s->mesh->comments, "two squares, two texture pages") != NULL, "comments '%s'", s->mesh->comments);
    rs_image *pages = NULL;
    RS_REQUIRE(rs_import_load_pages(s, &pages, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(!pages[0].pixels && pages[1].width == 4 && pages[2].width == 4, "page sizes");
    rs_pack_report rep;
    rs_splat_cloud *c = convert(s, pages, 4000, &rep);
    if (c) {
        // Both squares are kept (joined along the edge they share by position) and each is coloured by
        // its own page: red left of x = 1, blue right of it.
        RS_CHECK(rep.triangles_dropped == 0, "%u triangles dropped", rep.triangles_dropped);
        uint32_t wrong = 0, left = 0;
        for (uint32_t i = 0; i < c->hdr.count; i++) {
            rs_splat sp;
            rs_splat_get(c, i, &sp);
            bool is_left = sp.pos[0] < 1.0f;
            left += is_left;
            bool red = sp.rgb[0] > 150 && sp.rgb[2] < 100, blue = sp.rgb[2] > 150 && sp.rgb[0] < 100;
            wrong += is_left ? !red : !blue;
        }
        RS_CHECK(wrong == 0, "%u of %u splats coloured from the other page", wrong, c->hdr.count);
        RS_CHECK(left > c->hdr.count / 3 && left < 2 * c->hdr.count / 3, "%u of %u on the left square", left, c->hdr.count);
    }
    rs_splat_destroy(c);
    rs_import_free_pages(pages, s->page_count);
    rs_import_destroy(s);
}

static void test_glb_embedded_texture_and_metres(void)
{
    rs_error err = {0};
    rs_import_scene *s = NULL;
    RS_REQUIRE(rs_import_load(FX "square.glb", &s, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(s->format == RS_IMPORT_GLTF && s->declared_mm_per_unit == 1000.0f && s->v_flipped, "format %d, unit %g",
             s->format, s->declared_mm_per_unit);
    RS_CHECK(s->page_count >= 1 && s->pages[0].embedded && !s->pages[0].texture && !strcmp(s->pages[0].name, "green"),
             "embedded page");
    RS_CHECK(strstr(s->mesh->comments, "copyright: CC0 rouge test fixture") != NULL, "comments '%s'", s->mesh->comments);
    rs_image *pages = NULL;
    RS_REQUIRE(rs_import_load_pages(s, &pages, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(pages[0].width == 2 && pages[0].height == 2 && pages[0].pixels[1] == 200, "decoded embedded PNG");
    rs_pack_report rep;
    rs_splat_cloud *c = convert(s, pages, 1000, &rep);
    if (c) {
        rs_splat sp;
        rs_splat_get(c, 0, &sp);
        RS_CHECK(sp.rgb[0] == 40 && sp.rgb[1] == 200 && sp.rgb[2] == 60, "colour %u %u %u", sp.rgb[0], sp.rgb[1], sp.rgb[2]);
    }
    rs_splat_destroy(c);
    rs_import_free_pages(pages, s->page_count);
    rs_import_destroy(s);
}

static void test_vertex_colours_without_texture(void)
{
    rs_error err = {0};
    rs_import_scene *s = NULL;
    RS_REQUIRE(rs_import_load(FX "vertex_colours.obj", &s, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(s->mesh->rgb && s->mesh->tri_count == 2 && !s->mesh->tri_page, "rgb %p, %u triangles", (void *)s->mesh->rgb,
             s->mesh->tri_count);
    rs_pack_report rep;
    rs_splat_cloud *c = convert(s, NULL, 2000, &rep);
    if (c) {
        // Red along y = 0, blue along y = 1, interpolated between.
        uint32_t bad = 0;
        for (uint32_t i = 0; i < c->hdr.count; i++) {
            rs_splat sp;
            rs_splat_get(c, i, &sp);
            float y = RS_CLAMP(sp.pos[1], 0.0f, 1.0f);
            bad += abs((int)sp.rgb[0] - (int)lrintf(255 * (1 - y))) > 12 || abs((int)sp.rgb[2] - (int)lrintf(255 * y)) > 12;
        }
        RS_CHECK(bad == 0 && !rep.colour_default, "%u splats off the vertex-colour gradient", bad);
    }
    rs_splat_destroy(c);
    rs_import_destroy(s);
}

static void test_stl_and_ply_route(void)
{
    rs_error err = {0};
    rs_import_scene *s = NULL;
    RS_REQUIRE(rs_import_load(FX "tetra.stl", &s, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(s->format == RS_IMPORT_STL && s->mesh->vertex_count == 4 && s->mesh->tri_count == 4, "%u vertices, %u tris",
             s->mesh->vertex_count, s->mesh->tri_count);
    rs_import_destroy(s);
    s = NULL;
    // PLY goes to rouge's own reader (its messages, its comments).
    RS_REQUIRE(rs_import_load("tests/fixtures/ply/mesh_st.ply", &s, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(s->format == RS_IMPORT_PLY && s->mesh->texture_file && s->page_count == 0, "PLY route");
    rs_import_destroy(s);
    s = NULL;
    RS_CHECK(rs_import_load("tests/fixtures/ply/bad_truncated.ply", &s, &err) != RS_OK && strstr(err.msg, "bad_truncated.ply"),
             "bad PLY: %s", err.msg);
}

static void test_bad_models_fail_with_one_line(void)
{
    static const struct {
        const char *file, *want;
    } cases[] = {
        {FX "bad_truncated.glb", "bad glTF 2.0 file (assimp: "},
        {FX "bad_not_a_model.obj", "bad Wavefront OBJ file (assimp: "},
        {"tests/fixtures/image/a_8x8.png", "not a model rouge-pack can read (PLY, OBJ, glTF/GLB"},
        {FX "no_such_file.obj", "cannot open"},
        {"/dev/zero", "not a regular file"},
        {FX, "not a regular file"},
    };
    for (size_t i = 0; i < RS_COUNT_OF(cases); i++) {
        rs_error err = {0};
        rs_import_scene *s = NULL;
        rs_result r = rs_import_load(cases[i].file, &s, &err);
        RS_CHECK(r != RS_OK && !s && strstr(err.msg, cases[i].want) && !strchr(err.msg, '\n'), "%s: %s", cases[i].file, err.msg);
        rs_import_destroy(s);
    }
    // A material naming a texture that is not there: the model loads, its pages do not.
    rs_error err = {0};
    rs_import_scene *s = NULL;
    RS_REQUIRE(rs_import_load(FX "bad_missing_texture.obj", &s, &err) == RS_OK, "%s", err.msg);
    rs_image *pages = NULL;
    RS_CHECK(rs_import_load_pages(s, &pages, &err) != RS_OK && !pages && strstr(err.msg, "'no such file.jpg', which is not there"),
             "%s", err.msg);
    rs_import_destroy(s);
}

// The same model from memory (the fuzz harness's path) reads like the file.
static void test_memory_import_matches_file(void)
{
    void *data;
    size_t len;
    rs_error err = {0};
    RS_REQUIRE(rs_file_read_all(FX "square.glb", 1 << 20, &data, &len, &err) == RS_OK, "%s", err.msg);
    rs_import_scene *a = NULL, *b = NULL;
    RS_CHECK(rs_import_load_memory(data, len, "glb", &a, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(rs_import_load(FX "square.glb", &b, &err) == RS_OK, "%s", err.msg);
    if (a && b)
        RS_CHECK(a->mesh->vertex_count == b->mesh->vertex_count &&
                     !memcmp(a->mesh->pos, b->mesh->pos, (size_t)a->mesh->vertex_count * sizeof *a->mesh->pos) &&
                     a->pages[0].embedded_len == b->pages[0].embedded_len,
                 "memory and file imports differ");
    rs_import_destroy(a);
    rs_import_destroy(b);
    free(data);
    // From memory, a model cannot reach files beside it (an OBJ's MTL is just missing).
    a = NULL;
    RS_REQUIRE(rs_file_read_all(FX "two_pages.obj", 1 << 20, &data, &len, &err) == RS_OK, "%s", err.msg);
    if (rs_import_load_memory(data, len, "obj", &a, &err) == RS_OK)
        for (uint32_t i = 0; i < a->page_count; i++) RS_CHECK(!a->pages[i].texture && !a->pages[i].embedded, "MTL was read");
    rs_import_destroy(a);
    free(data);
}

// The bundled head's own GLB (shared data): imported like its PLY export (same vertices, triangles and
// UVs, same skin component) and converted with its face found.
static void test_lee_perry_smith_glb_matches_ply(void)
{
    // rs_test_shared_path returns one buffer: copy each path.
    char glb[512], ply[512];
    const char *p = rs_test_shared_path("leeperrysmith/source/LeePerrySmith.glb");
    snprintf(glb, sizeof glb, "%s", p ? p : "");
    p = rs_test_shared_path("leeperrysmith/head_mesh.ply");
    snprintf(ply, sizeof ply, "%s", p ? p : "");
    if (!glb[0] || !ply[0]) {
        rs_test_skip("shared data leeperrysmith/ not present");
        return;
    }
    rs_error err = {0};
    rs_import_scene *s = NULL;
    rs_ply_mesh *m = NULL;
    RS_REQUIRE(rs_import_load(glb, &s, &err) == RS_OK, "%s", err.msg);
    RS_REQUIRE(rs_ply_load(ply, &m, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(s->mesh->tri_count == m->tri_count && s->mesh->uv && s->mesh->normal, "%u triangles, PLY %u", s->mesh->tri_count,
             m->tri_count);
    // Every GLB triangle's corners equal the PLY's (positions within float rounding; v flipped back).
    double worst = 0, worst_uv = 0;
    for (uint32_t t = 0; t < RS_MIN(s->mesh->tri_count, m->tri_count); t++)
        for (int c = 0; c < 3; c++) {
            const float *a = s->mesh->pos[s->mesh->tri[t][c]], *b = m->pos[m->tri[t][c]];
            for (int k = 0; k < 3; k++) worst = fmax(worst, fabs(a[k] - b[k]));
            worst_uv = fmax(worst_uv, fabs(s->mesh->uv[s->mesh->tri[t][c]][0] - m->uv[m->tri[t][c]][0]));
            worst_uv = fmax(worst_uv, fabs(1.0 - s->mesh->uv[s->mesh->tri[t][c]][1] - m->uv[m->tri[t][c]][1]));
        }
    RS_CHECK(worst < 1e-5 && worst_uv < 1e-5, "largest position difference %g, UV %g", worst, worst_uv);
    rs_pack_report rep;
    rs_pack_desc d = {.points = 20000};
    rs_splat_cloud *c = NULL;
    RS_CHECK(rs_pack_convert(s->mesh, &d, &c, &rep, &err) == RS_OK, "%s", err.msg);
    // The skin island only, as from the PLY (the README's 15026 skin triangles; welding may join a
    // few sliver triangles of the seams).
    RS_CHECK(c && rep.face.found && rep.input_triangles - rep.triangles_dropped >= 15026 &&
                 rep.input_triangles - rep.triangles_dropped <= 15030,
             "face %d, %u triangles kept", rep.face.found, rep.input_triangles - rep.triangles_dropped);
    rs_splat_destroy(c);
    rs_ply_destroy(m);
    rs_import_destroy(s);
}

static void test_jpeg_and_png_textures_decode_with_limits(void)
{
    rs_error err = {0};
    rs_image img = {0};
    RS_REQUIRE(rs_image_load_any(FX "yellow 16.jpg", &img, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(img.width == 16 && img.height == 16 && img.channels == 3 && abs(img.pixels[0] - 240) < 6 &&
                 abs(img.pixels[1] - 200) < 6 && abs(img.pixels[2] - 20) < 8,
             "%dx%d, %u %u %u", img.width, img.height, img.pixels[0], img.pixels[1], img.pixels[2]);
    rs_image_free(&img);
    RS_CHECK(rs_image_load_any(FX "page one.png", &img, &err) == RS_OK && img.pixels[0] == 220, "%s", err.msg);
    rs_image_free(&img);
    static const struct {
        const char *file, *want;
        rs_result code;
    } bad[] = {
        {FX "bad_truncated.jpg", "JPEG is truncated", RS_ERR_FORMAT},
        {FX "bad_huge.jpg", "16000x16000 = 256.0 Mpx, more than the 67 Mpx allowed", RS_ERR_LIMIT},
        {FX "bad_bomb.jpg", "cannot hold that much data", RS_ERR_FORMAT},
        {FX "two_pages.obj", "not a PNG or JPEG file (starts 23 20 72 6f)", RS_ERR_FORMAT},
        {"tests/fixtures/bad/png_huge_dimensions.png", "larger than the 16384 allowed", RS_ERR_LIMIT},
        {"tests/fixtures/bad/png_truncated.png", "truncated", RS_ERR_FORMAT},
        {"/dev/zero", "not a regular file", RS_ERR_IO},
    };
    for (size_t i = 0; i < RS_COUNT_OF(bad); i++) {
        img = (rs_image){0};
        rs_result r = rs_image_load_any(bad[i].file, &img, &err);
        RS_CHECK(r == bad[i].code && !img.pixels && strstr(err.msg, bad[i].want), "%s: %s (%s)", bad[i].file, err.msg,
                 rs_result_name(r));
    }
}

int main(int argc, char **argv)
{
    rs_test_init(argc, argv);
    RS_RUN(test_obj_two_pages_sample_each_face_from_its_page);
    RS_RUN(test_glb_embedded_texture_and_metres);
    RS_RUN(test_vertex_colours_without_texture);
    RS_RUN(test_stl_and_ply_route);
    RS_RUN(test_bad_models_fail_with_one_line);
    RS_RUN(test_memory_import_matches_file);
    RS_RUN(test_jpeg_and_png_textures_decode_with_limits);
    RS_RUN(test_lee_perry_smith_glb_matches_ply);
    return rs_test_finish();
}
