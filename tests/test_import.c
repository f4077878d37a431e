// test_import.c — rouge-pack's import (tools/pack/import.h): models through assimp into the converter's
// mesh, texture pages, embedded images, vertex colours, declared units and the scale rule, bad inputs;
// and the face frame of a scan in any orientation, also of a face-only scan.
#define _POSIX_C_SOURCE 200809L
#include "support/harness.h"
#include "pack/import.h"
#include "pack/pack.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <jpeglib.h>

#define FX "tests/fixtures/import/"

static rs_splat_cloud *convert(const rs_import_scene *s, const rs_image *pages, uint32_t points, rs_pack_report *rep)
{
    rs_error err = {0};
    // (No ambient occlusion: these checks read colours and counts; occlusion was most of the conversion.)
    rs_pack_desc d = {.points = points, .pages = pages, .page_count = pages ? s->page_count : 0, .mm_per_unit = 1,
                      .no_ao = true};
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
    RS_REQUIRE(rs_import_load_pages(s, &pages, NULL, 0, &err) == RS_OK, "%s", err.msg);
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
    RS_REQUIRE(rs_import_load_pages(s, &pages, NULL, 0, &err) == RS_OK, "%s", err.msg);
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
    // A material naming a texture that is not there: the model loads, its page stays empty with a warning.
    rs_error err = {0};
    rs_import_scene *s = NULL;
    RS_REQUIRE(rs_import_load(FX "bad_missing_texture.obj", &s, &err) == RS_OK, "%s", err.msg);
    rs_image *pages = NULL;
    char warn[1024] = "";
    RS_CHECK(rs_import_load_pages(s, &pages, warn, sizeof warn, &err) == RS_OK && pages && strstr(warn, "'no such file.jpg', which is not there"),
             "%s", warn);
    for (uint32_t i = 0; pages && i < s->page_count; i++) RS_CHECK(!pages[i].pixels, "page %u has pixels", i);
    rs_import_free_pages(pages, s->page_count);
    rs_import_destroy(s);
}

// Hostile structure is refused in this process before assimp reads it (the memory import is the fuzz
// harness's path, with no child process behind it): deep nesting, a cycle of instances, a node instanced
// past the unrolled-node limit, an FBX array claiming more than its compressed bytes hold.
static void test_guard_refuses_hostile_structure(void)
{
    size_t cap = 1 << 20, n = 0;
    char *deep = malloc(cap);
    RS_REQUIRE(deep, "out of memory");
    // JSON nested 300 deep, and a glTF whose node 1 lists itself as a child.
    for (int i = 0; i < 300; i++) deep[n++] = '[';
    for (int i = 0; i < 300; i++) deep[n++] = ']';
    static const char cycle[] = "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"children\":[1]},{\"children\":[2]},{\"children\":[1]}]}";
    // A chain of 30 COLLADA nodes each instancing the next one twice: 2^30 nodes once unrolled.
    char *dae = malloc(cap);
    RS_REQUIRE(dae, "out of memory");
    size_t m = (size_t)snprintf(dae, cap, "<COLLADA><library_nodes>");
    for (int i = 0; i < 30; i++)
        m += (size_t)snprintf(dae + m, cap - m, "<node id=\"n%d\"><instance_node url=\"#n%d\"/><instance_node url=\"#n%d\"/></node>",
                              i, i + 1, i + 1);
    m += (size_t)snprintf(dae + m, cap - m, "<node id=\"n30\"/></library_nodes></COLLADA>");
    // FBX 7.4: one record whose 'd' array claims 2^28 - 1 doubles from 8 zlib bytes.
    uint8_t fbx[128] = "Kaydara FBX Binary  \0\x1a\0";
    size_t f = 23;
    rs_le32_put(fbx + f, 7400), f += 4;
    size_t rec = f;
    f += 13;  // end offset, property count, property bytes, name length: filled below
    memcpy(fbx + f, "Vertices", 8), f += 8;
    fbx[f++] = 'd';
    rs_le32_put(fbx + f, (1u << 28) - 1), rs_le32_put(fbx + f + 4, 1), rs_le32_put(fbx + f + 8, 8), f += 12;
    memcpy(fbx + f, "\x78\x9c\x03\x00\x00\x00\x00\x01", 8), f += 8;
    rs_le32_put(fbx + rec, (uint32_t)f), rs_le32_put(fbx + rec + 4, 1), rs_le32_put(fbx + rec + 8, 21), fbx[rec + 12] = 8;
    f += 13;  // the closing null record
    struct {
        const void *data;
        size_t len;
        const char *hint, *want;
    } cases[] = {
        {deep, n, "gltf", "JSON objects and arrays nested more than 256 deep"},
        {cycle, sizeof cycle - 1, "gltf", "glTF node 1 contains itself"},
        {dae, m, "dae", "unrolls to more than 1048576 nodes"},
        {fbx, f, "fbx", "claims 2147483640 bytes from 8 stored bytes"},
    };
    for (size_t i = 0; i < RS_COUNT_OF(cases); i++) {
        rs_error err = {0};
        RS_CHECK(rs_import_guard(cases[i].data, cases[i].len, RS_IMPORT_OTHER, "x", &err) != RS_OK &&
                     strstr(err.msg, cases[i].want), "case %zu: %s", i, err.msg);
        rs_import_scene *s = NULL;
        RS_CHECK(rs_import_load_memory(cases[i].data, cases[i].len, cases[i].hint, &s, &err) != RS_OK && !s &&
                     strstr(err.msg, cases[i].want) && !strchr(err.msg, '\n'), "case %zu: %s", i, err.msg);
        rs_import_destroy(s);
    }
    // The fixtures people's files look like pass.
    void *data;
    size_t len;
    rs_error err = {0};
    RS_REQUIRE(rs_file_read_all(FX "square.glb", 1 << 20, &data, &len, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(rs_import_guard(data, len, RS_IMPORT_GLTF, "square.glb", &err) == RS_OK, "%s", err.msg);
    // COLLADA nodes none of which has an id (make fuzz's find: the id table was then sorted and searched as
    // a null pointer, undefined behaviour): nothing to resolve, not an error.
    static const char no_ids[] = "<COLLADA><library_nodes><node><instance_node url=\"#n\"/></node></library_nodes></COLLADA>";
    RS_CHECK(rs_import_guard(no_ids, sizeof no_ids - 1, RS_IMPORT_OTHER, "x", &err) == RS_OK, "%s", err.msg);
    // An image whose mimeType has no '/' (make fuzz's find: assimp then read from address 1 and crashed) is
    // refused before assimp sees it; a proper one passes.
    static const char mime_bad[] = "{\"asset\":{\"version\":\"2.0\"},\"images\":[{\"bufferView\":0, \"mimeType\" : \"image?png\"}]}";
    static const char mime_ok[] = "{\"asset\":{\"version\":\"2.0\"},\"images\":[{\"bufferView\":0,\"mimeType\":\"image/png\"}]}";
    RS_CHECK(rs_import_guard(mime_bad, sizeof mime_bad - 1, RS_IMPORT_GLTF, "x", &err) == RS_ERR_FORMAT &&
                 strstr(err.msg, "mimeType is not of the form type/subtype"), "%s", err.msg);
    RS_CHECK(rs_import_guard(mime_ok, sizeof mime_ok - 1, RS_IMPORT_GLTF, "x", &err) == RS_OK, "%s", err.msg);
    free(data);
    free(deep);
    free(dae);
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
        {FX "two_pages.obj", "not a PNG, JPEG, BMP or TGA file (starts 23 20 72 6f)", RS_ERR_FORMAT},
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

// The scale rule (pack.h): a given unit wins; a declared one is used when the head it gives is a head;
// else the one standard unit that makes the head 150..300 mm; else the head is taken as 225 mm. The
// committed OBJ head is 4.7 units tall: scaled to mm, cm and m it must read as those units.
static void test_scale_rule_reads_units_from_the_head(void)
{
    rs_error err = {0};
    rs_import_scene *s = NULL;
    RS_REQUIRE(rs_import_load(FX "head/head.obj", &s, &err) == RS_OK, "%s", err.msg);
    rs_ply_mesh *m = s->mesh;
    float(*orig)[3] = malloc((size_t)m->vertex_count * sizeof *orig);
    RS_REQUIRE(orig, "out of memory");
    memcpy(orig, m->pos, (size_t)m->vertex_count * sizeof *orig);
    static const struct {
        float scale, given, declared;  // positions x scale; desc.mm_per_unit; desc.declared_mm_per_unit
        rs_pack_scale want;
        float want_mm;                 // 0: the estimate, 225 mm / face height
    } cases[] = {
        {47.0f, 0, 0, RS_PACK_SCALE_INFERRED, 1.0f},        // millimetres
        {4.7f, 0, 0, RS_PACK_SCALE_INFERRED, 10.0f},        // centimetres
        {0.047f, 0, 0, RS_PACK_SCALE_INFERRED, 1000.0f},    // metres
        {1.85f, 0, 0, RS_PACK_SCALE_INFERRED, 25.4f},       // inches
        {1.0f, 0, 0, RS_PACK_SCALE_ESTIMATED, 0},           // 4.7 units: no unit gives a head
        {1.0f, 0, 1000.0f, RS_PACK_SCALE_ESTIMATED, 0},     // "metres" for a 4.7 m head: ignored
        {0.047f, 0, 1000.0f, RS_PACK_SCALE_DECLARED, 1000.0f},
        {0.08f, 0, 1000.0f, RS_PACK_SCALE_DECLARED, 1000.0f},  // a big (375 mm) head: declared still holds
        {47.0f, 2.0f, 1000.0f, RS_PACK_SCALE_GIVEN, 2.0f},
    };
    for (size_t k = 0; k < RS_COUNT_OF(cases); k++) {
        for (uint32_t i = 0; i < m->vertex_count; i++)
            for (int a = 0; a < 3; a++) m->pos[i][a] = orig[i][a] * cases[k].scale;
        // (No ambient occlusion: the unit rule reads the face, and occlusion was most of each conversion. The
        // face comes from a sample of its own whatever --points asks, so a few thousand splats do.)
        rs_pack_desc d = {.points = 3000, .mm_per_unit = cases[k].given, .declared_mm_per_unit = cases[k].declared,
                          .declared_unit = "test", .no_ao = true};
        rs_pack_report rep;
        rs_splat_cloud *c = NULL;
        if (!RS_CHECK(rs_pack_convert(m, &d, &c, &rep, &err) == RS_OK, "case %zu: %s", k, err.msg)) continue;
        float want = cases[k].want_mm ? cases[k].want_mm : RS_PACK_ASSUMED_HEAD_MM / c->hdr.face_height;
        RS_CHECK(rep.face.found && rep.scale == cases[k].want && fabsf(c->hdr.mm_per_unit - want) < 1e-3f * want,
                 "case %zu (x%g): rule %d, %g mm per unit (%s); wanted rule %d, %g", k, cases[k].scale, rep.scale,
                 c->hdr.mm_per_unit, rep.scale_why, cases[k].want, want);
        rs_splat_destroy(c);
    }
    free(orig);
    rs_import_destroy(s);
    RS_CHECK(rs_pack_unit_parse("mm") == 1.0f && rs_pack_unit_parse("in") == 25.4f && rs_pack_unit_parse("m") == 1000.0f &&
                 rs_pack_unit_parse("ft") == 0 && rs_pack_unit_parse(NULL) == 0,
             "unit names");
}

// ---- the face frame in any orientation, and face-only scans (tools/pack/pack_frame.c, pack_face.c) ----
// On a 40k LOD prefix of the bundled face (assets/face.rsf), so no shared data is needed.

#define N_POINTS 40000

typedef struct scan {
    uint32_t n;
    float (*pos)[3], (*nrm)[3];
} scan;

static float dot3(const float a[3], const float b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static double angle_deg(const float a[3], const float b[3])
{
    return acos(RS_CLAMP(dot3(a, b), -1.0f, 1.0f)) * 57.29577951;
}

static bool load_face(scan *s)
{
    rs_splat_cloud *c = NULL;
    rs_error err = {0};
    if (!RS_CHECK(rs_splat_load("assets/face.rsf", &c, &err) == RS_OK, "%s", err.msg)) return false;
    s->n = rs_splat_lod_count(c, N_POINTS);
    s->pos = malloc((size_t)s->n * sizeof *s->pos);
    s->nrm = malloc((size_t)s->n * sizeof *s->nrm);
    for (uint32_t i = 0; i < s->n; i++) {
        rs_splat sp;
        rs_splat_get(c, i, &sp);
        memcpy(s->pos[i], sp.pos, sizeof sp.pos);
        memcpy(s->nrm[i], sp.normal, sizeof sp.normal);
    }
    rs_splat_destroy(c);
    return true;
}

static void scan_free(scan *s)
{
    free(s->pos);
    free(s->nrm);
}

// A uniformly random rotation (Shoemake's quaternion from three uniforms) as a matrix.
static void random_rotation(rs_pack_rng *r, float m[3][3])
{
    double u1 = rs_pack_rng_unit(r), u2 = rs_pack_rng_unit(r) * 6.283185307, u3 = rs_pack_rng_unit(r) * 6.283185307;
    double a = sqrt(1 - u1), b = sqrt(u1);
    double x = a * sin(u2), y = a * cos(u2), z = b * sin(u3), w = b * cos(u3);
    double q[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
                      {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
                      {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) m[i][j] = (float)q[i][j];
}

static void apply(const float m[3][3], const float v[3], const float t[3], float out[3])
{
    float r[3];
    for (int i = 0; i < 3; i++) r[i] = m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2] + (t ? t[i] : 0);
    memcpy(out, r, sizeof r);
}

// Face frame and regions of a scan with no axes given.
static bool analyse(const scan *s, rs_pack_face *f, uint8_t *region)
{
    rs_error err = {0};
    if (!RS_CHECK(rs_pack_find_face((const float(*)[3])s->pos, (const float(*)[3])s->nrm, s->n, RS_PACK_AXIS_DEFAULT,
                                    RS_PACK_AXIS_DEFAULT, f, &err) == RS_OK, "%s", err.msg))
        return false;
    memset(region, RS_PACK_REGION_AUTO, s->n);
    rs_pack_segment((const float(*)[3])s->pos, (const float(*)[3])s->nrm, s->n, f, region);
    return true;
}

// Compares a frame found on a moved scan with the reference frame moved the same way.
// Tolerances: angles in degrees, the face height as a fraction, the least fraction of equal region labels.
typedef struct tol {
    double angle, height, agree;
} tol;

static void compare(const char *what, const rs_pack_face *ref, const float m[3][3], const float t[3], const rs_pack_face *got,
                    const uint8_t *ref_region, const uint8_t *region, const uint32_t *ids, uint32_t n, tol tl)
{
    float fw[3], up[3], nose[3], centre[3];
    apply(m, ref->forward, NULL, fw);
    apply(m, ref->up, NULL, up);
    apply(m, ref->nose_tip, t, nose);
    apply(m, ref->centre, t, centre);
    float dn[3] = {nose[0] - got->nose_tip[0], nose[1] - got->nose_tip[1], nose[2] - got->nose_tip[2]};
    double a_fw = angle_deg(fw, got->forward), a_up = angle_deg(up, got->up), d_nose = sqrt(dot3(dn, dn)) / ref->face_height;
    uint32_t same = 0;
    for (uint32_t i = 0; i < n; i++) same += region[i] == ref_region[ids ? ids[i] : i];
    double agree = (double)same / n;
    printf("# %s: forward %.2f deg, up %.2f deg, nose tip %.4f H, face height %.3f vs %.3f, regions agree %.1f%%\n", what,
           a_fw, a_up, d_nose, got->face_height, ref->face_height, 100 * agree);
    RS_CHECK(got->found && a_fw < tl.angle && a_up < tl.angle && d_nose < 0.01 &&
                 fabs(got->face_height - ref->face_height) < tl.height * ref->face_height && agree >= tl.agree,
             "%s: found %d, forward off by %.2f deg, up %.2f deg, nose tip %.4f H, face height %.3f vs %.3f, regions agree "
             "%.1f%%",
             what, got->found, a_fw, a_up, d_nose, got->face_height, ref->face_height, 100 * agree);
}

static void test_frame_survives_random_rotations(void)
{
    scan s;
    if (!load_face(&s)) return;
    rs_pack_face ref;
    uint8_t *ref_region = malloc(s.n), *region = malloc(s.n);
    scan r = {.n = s.n, .pos = malloc((size_t)s.n * sizeof *s.pos), .nrm = malloc((size_t)s.n * sizeof *s.nrm)};
    if (analyse(&s, &ref, ref_region)) {
        RS_CHECK(ref.found && ref.up[1] > 0.98f && ref.forward[2] > 0.98f, "upright scan: up %.3f %.3f %.3f, forward %.3f %.3f %.3f",
                 ref.up[0], ref.up[1], ref.up[2], ref.forward[0], ref.forward[1], ref.forward[2]);
        rs_pack_rng rng;
        rs_pack_rng_seed(&rng, 1414);
        for (int k = 0; k < 8; k++) {
            float m[3][3], t[3] = {(float)rs_pack_rng_unit(&rng) * 20 - 10, (float)rs_pack_rng_unit(&rng) * 20 - 10,
                                   (float)rs_pack_rng_unit(&rng) * 20 - 10};
            random_rotation(&rng, m);
            for (uint32_t i = 0; i < s.n; i++) {
                apply(m, s.pos[i], t, r.pos[i]);
                apply(m, s.nrm[i], NULL, r.nrm[i]);
            }
            rs_pack_face got;
            char what[32];
            snprintf(what, sizeof what, "rotation %d", k);
            if (analyse(&r, &got, region)) compare(what, &ref, m, t, &got, ref_region, region, NULL, s.n, (tol){3, 0.03, 0.97});
        }
    }
    free(ref_region);
    free(region);
    scan_free(&r);
    scan_free(&s);
}

// A face-only scan (what a phone's front camera captures): the points in front of the ears, none of the
// back of the head or the neck below the chin, in a random orientation. It must still find the face and
// label the skin regions as on the whole head.
static void test_partial_scan_keeps_face_and_regions(void)
{
    scan s;
    if (!load_face(&s)) return;
    rs_pack_face ref;
    uint8_t *ref_region = malloc(s.n), *region = malloc(s.n);
    uint32_t *ids = malloc((size_t)s.n * sizeof *ids);
    scan p = {.pos = malloc((size_t)s.n * sizeof *s.pos), .nrm = malloc((size_t)s.n * sizeof *s.nrm)};
    if (analyse(&s, &ref, ref_region)) {
        float H = ref.face_height;
        for (uint32_t i = 0; i < s.n; i++) {
            float d[3] = {s.pos[i][0] - ref.nose_tip[0], s.pos[i][1] - ref.nose_tip[1], s.pos[i][2] - ref.nose_tip[2]};
            float df = dot3(d, ref.forward) / H, du = dot3(d, ref.up) / H;
            if (df < -0.3f || du < -0.42f || du > 0.36f) continue;  // cut at the hairline and before the ears; chin in
            ids[p.n++] = i;
        }
        rs_pack_rng rng;
        rs_pack_rng_seed(&rng, 77);
        float m[3][3], t[3] = {3, -2, 5};
        random_rotation(&rng, m);
        for (uint32_t j = 0; j < p.n; j++) {
            apply(m, s.pos[ids[j]], t, p.pos[j]);
            apply(m, s.nrm[ids[j]], NULL, p.nrm[j]);
        }
        rs_pack_face got;
        if (analyse(&p, &got, region)) {
            // The face height comes from the lips here (no crown), so a little more slack.
            RS_CHECK(!got.crown, "the face-only scan has a crown");
            compare("face-only scan", &ref, m, t, &got, ref_region, region, ids, p.n, (tol){5, 0.08, 0.90});
            uint32_t lips = 0, nose = 0, cheek = 0, forehead = 0;
            for (uint32_t j = 0; j < p.n; j++) {
                lips += region[j] == RS_REGION_LIPS;
                nose += region[j] == RS_REGION_NOSE;
                cheek += region[j] == RS_REGION_CHEEK;
                forehead += region[j] == RS_REGION_FOREHEAD;
            }
            RS_CHECK(lips && nose && cheek && forehead, "regions: lips %u nose %u cheek %u forehead %u of %u", lips, nose, cheek,
                     forehead, p.n);
        }
    }
    free(ref_region);
    free(region);
    free(ids);
    scan_free(&p);
    scan_free(&s);
}


// ---- textures of every kind (issue 24, item 1), fixtures written here ----

// An 8x2 image, left half red (220 30 30), right half blue (30 30 220), as `kind`: "bmp" (24-bit,
// bottom-up rows padded to 4 bytes), "tga" (uncompressed 24-bit, bottom-up) or "tga_rle" (run-length).
static bool write_halves(const char *path, const char *kind)
{
    enum { W = 8, H = 2 };
    uint8_t buf[512];
    size_t n = 0;
    bool bmp = !strcmp(kind, "bmp"), rle = !strcmp(kind, "tga_rle");
    if (bmp) {
        uint32_t row = (W * 3 + 3) & ~3u, size = 54 + row * H;
        uint8_t h[54] = {'B', 'M', (uint8_t)size, (uint8_t)(size >> 8), 0, 0, 0, 0, 0, 0, 54, 0, 0, 0, 40, 0, 0, 0, W, 0, 0, 0,
                         H, 0, 0, 0, 1, 0, 24, 0};
        memcpy(buf, h, 54);
        n = 54;
    } else {
        uint8_t h[18] = {0, 0, rle ? 10 : 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, W, 0, H, 0, 24, 0};
        memcpy(buf, h, 18);
        n = 18;
    }
    for (int y = 0; y < H; y++) {
        if (rle) {
            // Two runs per row: 4 red pixels, 4 blue (packet header 0x80 | (count - 1), then one BGR pixel).
            const uint8_t red[4] = {0x83, 30, 30, 220}, blue[4] = {0x83, 220, 30, 30};
            memcpy(buf + n, red, 4), memcpy(buf + n + 4, blue, 4);
            n += 8;
            continue;
        }
        for (int x = 0; x < W; x++) {
            uint8_t b = x < W / 2 ? 30 : 220, r = x < W / 2 ? 220 : 30;
            buf[n++] = b, buf[n++] = 30, buf[n++] = r;
        }
        while (bmp && n % 4 != 54 % 4) buf[n++] = 0;
    }
    FILE *f = fopen(path, "wb");
    if (!f) return false;
    bool ok = fwrite(buf, 1, n, f) == n;
    return fclose(f) == 0 && ok;
}

// The same halves as a progressive JPEG (libjpeg's simple progression: what stb_image 2.27 refused),
// 64x16 so the colour survives the chroma subsampling.
static bool write_progressive_jpeg(const char *path)
{
    enum { W = 64, H = 16 };
    FILE *f = fopen(path, "wb");
    if (!f) return false;
    struct jpeg_compress_struct j;
    struct jpeg_error_mgr e;
    j.err = jpeg_std_error(&e);
    jpeg_create_compress(&j);
    jpeg_stdio_dest(&j, f);
    j.image_width = W, j.image_height = H, j.input_components = 3, j.in_color_space = JCS_RGB;
    jpeg_set_defaults(&j);
    jpeg_set_quality(&j, 95, TRUE);
    jpeg_simple_progression(&j);
    jpeg_start_compress(&j, TRUE);
    uint8_t row[W * 3];
    for (int x = 0; x < W; x++) row[3 * x] = x < W / 2 ? 220 : 30, row[3 * x + 1] = 30, row[3 * x + 2] = x < W / 2 ? 30 : 220;
    while (j.next_scanline < H) {
        JSAMPROW r = row;
        jpeg_write_scanlines(&j, &r, 1);
    }
    jpeg_finish_compress(&j);
    jpeg_destroy_compress(&j);
    return fclose(f) == 0;
}

static bool write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    if (!f) return false;
    bool ok = fputs(text, f) >= 0;
    return fclose(f) == 0 && ok;
}

// dir/name.obj: a 6 x 1 quad whose u runs 0..6 (a texture tiled six times), with dir/name.mtl holding
// `map_line` for its one material.
static bool write_tiled_quad(const char *dir, const char *name, const char *map_line)
{
    char obj[512], mtl[512], text[1024];
    snprintf(obj, sizeof obj, "%s/%s.obj", dir, name);
    snprintf(mtl, sizeof mtl, "%s/%s.mtl", dir, name);
    snprintf(text, sizeof text, "newmtl skin\nKd 1 1 1\n%s\n", map_line);
    if (!write_text(mtl, text)) return false;
    snprintf(text, sizeof text, "mtllib %s.mtl\nv 0 0 0\nv 6 0 0\nv 6 1 0\nv 0 1 0\nvt 0 0\nvt 6 0\nvt 6 1\nvt 0 1\n"
                                "usemtl skin\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n", name);
    return write_text(obj, text);
}

// Converts dir/name.obj with its pages; the fraction of splats that came out red (NaN when it did not
// convert), and the warnings in warn[cap].
static double red_fraction(const char *dir, const char *name, char *warn, size_t cap, uint32_t *textured)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s.obj", dir, name);
    rs_error err = {0};
    rs_import_scene *s = NULL;
    warn[0] = 0;
    *textured = 0;
    if (rs_import_load(path, &s, &err) != RS_OK) {
        RS_CHECK(false, "%s: %s", path, err.msg);
        return NAN;
    }
    snprintf(warn, cap, "%s", s->mesh->warnings);
    size_t len = strlen(warn);
    rs_image *pages = NULL;
    if (rs_import_load_pages(s, &pages, warn + len, cap - len, &err) != RS_OK) {
        RS_CHECK(false, "%s: %s", path, err.msg);
        rs_import_destroy(s);
        return NAN;
    }
    uint8_t(*wrap)[2] = calloc(s->page_count + 1, sizeof *wrap);
    for (uint32_t i = 0; i < s->page_count; i++) {
        *textured += pages[i].pixels != NULL;
        memcpy(wrap[i], s->pages[i].wrap, 2);
    }
    rs_pack_desc d = {.points = 3000, .pages = pages, .page_count = s->page_count, .page_wrap = (const uint8_t(*)[2])wrap,
                      .mm_per_unit = 1, .no_ao = true};
    rs_splat_cloud *c = NULL;
    rs_pack_report rep;
    double red = NAN;
    if (rs_pack_convert(s->mesh, &d, &c, &rep, &err) == RS_OK) {
        uint32_t n = 0;
        for (uint32_t i = 0; i < c->hdr.count; i++) {
            rs_splat sp;
            rs_splat_get(c, i, &sp);
            n += sp.rgb[0] > 150 && sp.rgb[2] < 100;
        }
        red = (double)n / c->hdr.count;
        RS_CHECK(rep.colour_default == (*textured == 0), "%s: colour_default %d with %u textured pages", name,
                 rep.colour_default, *textured);
    } else {
        RS_CHECK(false, "%s: %s", name, err.msg);
    }
    rs_splat_destroy(c);
    free(wrap);
    rs_import_free_pages(pages, s->page_count);
    rs_import_destroy(s);
    return red;
}

static void test_bmp_tga_and_progressive_jpeg_decode(void)
{
    char dir[512], path[600];
    snprintf(dir, sizeof dir, "%s/textures_of_every_kind", rs_test_out_dir());
    mkdir(dir, 0755);
    static const char *const kinds[] = {"bmp", "tga", "tga_rle", "jpg"};
    for (size_t k = 0; k < RS_COUNT_OF(kinds); k++) {
        snprintf(path, sizeof path, "%s/halves.%s", dir, kinds[k]);
        bool jpg = !strcmp(kinds[k], "jpg");
        RS_REQUIRE(jpg ? write_progressive_jpeg(path) : write_halves(path, kinds[k]), "cannot write %s", path);
        rs_error err = {0};
        rs_image img = {0};
        rs_result r = rs_image_load_any(path, &img, &err);
        RS_CHECK(r == RS_OK, "%s: %s", kinds[k], err.msg);
        if (r != RS_OK) continue;
        int w = jpg ? 64 : 8, tol = jpg ? 12 : 0;
        const uint8_t *left = img.pixels + 3 * 1, *right = img.pixels + 3 * (w - 2);
        RS_CHECK(img.width == w && img.height == (jpg ? 16 : 2) && img.channels == 3, "%s: %dx%dx%d", kinds[k], img.width,
                 img.height, img.channels);
        RS_CHECK(abs(left[0] - 220) <= tol && abs(left[2] - 30) <= tol && abs(right[0] - 30) <= tol && abs(right[2] - 220) <= tol,
                 "%s: left %u %u %u, right %u %u %u", kinds[k], left[0], left[1], left[2], right[0], right[1], right[2]);
        rs_image_free(&img);
    }
    // Embedded images take the same decoder: a TGA's bytes from memory (no signature to go by).
    void *data;
    size_t len;
    rs_error err = {0};
    snprintf(path, sizeof path, "%s/halves.tga_rle", dir);
    RS_REQUIRE(rs_file_read_all(path, 1 << 20, &data, &len, &err) == RS_OK, "%s", err.msg);
    rs_image img = {0};
    RS_CHECK(rs_image_decode_any(data, len, "embedded", &img, &err) == RS_OK && img.width == 8, "%s", err.msg);
    rs_image_free(&img);
    free(data);
}

static void test_textures_wrap_resolve_and_never_stop_a_conversion(void)
{
    char dir[512], path[600];
    snprintf(dir, sizeof dir, "%s/textures_of_every_kind", rs_test_out_dir());
    mkdir(dir, 0755);
    snprintf(path, sizeof path, "%s/textures", dir);
    mkdir(path, 0755);
    snprintf(path, sizeof path, "%s/textures/skin.tga", dir);
    RS_REQUIRE(write_halves(path, "tga"), "cannot write %s", path);
    snprintf(path, sizeof path, "%s/skin.bmp", dir);
    RS_REQUIRE(write_halves(path, "bmp"), "cannot write %s", path);
    snprintf(path, sizeof path, "%s/skin.jpg", dir);
    RS_REQUIRE(write_progressive_jpeg(path), "cannot write %s", path);
    static const struct {
        const char *name, *map, *warn;  // warn: a warning it must give ("" none)
        double red_lo, red_hi;          // the red fraction: ~1/2 tiled, ~1/12 clamped, -1 untextured
    } cases[] = {
        // u 0..6 repeats the texture (it was clamped: the red half appeared once, at the left end).
        {"wrap_bmp", "map_Kd skin.bmp", "", 0.42, 0.58},
        {"wrap_progressive_jpeg", "map_Kd skin.jpg", "", 0.42, 0.58},
        // The material's own mode: MTL's -clamp on is AI_MATKEY_MAPPINGMODE_U/V = clamp.
        {"clamp_mode", "map_Kd -clamp on skin.bmp", "", 0.04, 0.13},
        // Windows paths: a leading backslash (a DAE's) and a drive letter name files below the folder.
        {"backslash_path", "map_Kd \\textures\\skin.tga", "", 0.42, 0.58},
        {"drive_letter_path", "map_Kd C:\\work\\scans\\skin.bmp", "", 0.42, 0.58},
        // Missing, placeholder and unreadable textures warn, and the model converts in the default grey.
        {"missing", "map_Kd gone.png", "'gone.png', which is not there", -1, -1},
        {"placeholder", "map_Kd $texture_dummy.bmp", "placeholder texture '$texture_dummy.bmp' (the file names no texture assimp found); coloured from the default grey instead", -1, -1},
        {"unreadable", "map_Kd halves_wrong.png", "not a PNG, JPEG, BMP or TGA file", -1, -1},
    };
    snprintf(path, sizeof path, "%s/halves_wrong.png", dir);
    RS_REQUIRE(write_text(path, "this is not an image at all, only words"), "cannot write %s", path);
    for (size_t i = 0; i < RS_COUNT_OF(cases); i++) {
        RS_REQUIRE(write_tiled_quad(dir, cases[i].name, cases[i].map), "cannot write %s", cases[i].name);
        char warn[2048];
        uint32_t textured = 0;
        double red = red_fraction(dir, cases[i].name, warn, sizeof warn, &textured);
        if (cases[i].red_lo < 0) {
            RS_CHECK(red == 0 && textured == 0, "%s: red %.3f, %u pages textured", cases[i].name, red, textured);
        } else {
            RS_CHECK(red >= cases[i].red_lo && red <= cases[i].red_hi && textured == 1, "%s: red %.3f (want %.2f..%.2f), %u textured",
                     cases[i].name, red, cases[i].red_lo, cases[i].red_hi, textured);
        }
        RS_CHECK(cases[i].warn[0] ? strstr(warn, cases[i].warn) != NULL : !warn[0], "%s: warnings '%s'", cases[i].name, warn);
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
    RS_RUN(test_guard_refuses_hostile_structure);
    RS_RUN(test_jpeg_and_png_textures_decode_with_limits);
    RS_RUN(test_bmp_tga_and_progressive_jpeg_decode);
    RS_RUN(test_textures_wrap_resolve_and_never_stop_a_conversion);
    RS_RUN(test_lee_perry_smith_glb_matches_ply);
    RS_RUN(test_scale_rule_reads_units_from_the_head);
    RS_RUN(test_frame_survives_random_rotations);
    RS_RUN(test_partial_scan_keeps_face_and_regions);
    return rs_test_finish();
}
