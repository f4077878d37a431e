// test_ply.c — the PLY reader: every supported variant decodes to the expected numbers, and every kind
// of malformed input fails with a one-line message naming what and where, without crashing (ASan).
// Fixtures: tests/fixtures/ply/ (see its README.md); malformed variants are derived here in memory.
#define _POSIX_C_SOURCE 200809L
#include "support/harness.h"
#include "pack/ply.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define FIXTURES "tests/fixtures/ply/"

// The cloud in points_{ascii,le,be,crlf,shuffled}.ply (make_fixtures.py: POS, NRM, RGB).
static const float POS[4][3] = {{0.5f, -1.25f, 2.0f}, {1.0f, 0.0f, -0.75f}, {-3.5f, 2.25f, 0.125f}, {100.0f, -0.0625f, 7.5f}};
static const float NRM[4][3] = {{0, 0, 1}, {0, 1, 0}, {1, 0, 0}, {0.5f, -0.5f, 0.75f}};
static const uint8_t RGB[4][3] = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {12, 34, 56}};

static const char ASCII_CLOUD[] =
    "ply\n"
    "format ascii 1.0\n"
    "comment test\n"
    "element vertex 3\n"
    "property float x\n"
    "property float y\n"
    "property float z\n"
    "property uchar red\n"
    "property uchar green\n"
    "property uchar blue\n"
    "end_header\n"
    "0 0 0 1 2 3\n"
    "1 0 0 4 5 6\n"
    "0 1 0 7 8 9\n";

static const char ASCII_MESH[] =
    "ply\n"
    "format ascii 1.0\n"
    "element vertex 3\n"
    "property float x\n"
    "property float y\n"
    "property float z\n"
    "element face 2\n"
    "property list uchar int vertex_indices\n"
    "end_header\n"
    "0 0 0\n"
    "1 0 0\n"
    "0 1 0\n"
    "3 0 1 2\n"
    "3 2 1 0\n";

// Parses from an exactly sized heap copy, so ASan reports any read past the end (the reader must
// never rely on a terminating NUL).
static rs_result parse_exact(const void *data, size_t len, rs_ply_mesh **m, rs_error *err)
{
    void *copy = malloc(len ? len : 1);
    if (!copy) return rs_fail(err, RS_ERR_NOMEM, "test: out of memory");
    if (len) memcpy(copy, data, len);
    rs_result r = rs_ply_load_memory(copy, len, m, err);
    free(copy);
    return r;
}

static rs_result parse_str(const char *s, rs_ply_mesh **m, rs_error *err)
{
    return parse_exact(s, strlen(s), m, err);
}

// Offset of the first `needle` in data[0..len) (no NUL needed), or SIZE_MAX.
static size_t find(const void *data, size_t len, const char *needle)
{
    size_t n = strlen(needle);
    for (size_t i = 0; i + n <= len; i++)
        if (memcmp((const char *)data + i, needle, n) == 0) return i;
    return SIZE_MAX;
}

// A malloc'd copy of data[0..len) with the first `from` replaced by `to` (NULL when absent), plus a NUL
// past the end so text can be used as a C string; *out_len (if non-NULL) gets the new length.
static char *replace_n(const void *data, size_t len, const char *from, const char *to, size_t *out_len)
{
    size_t at = find(data, len, from);
    if (at == SIZE_MAX) return NULL;
    size_t nf = strlen(from), nt = strlen(to), n = len - nf + nt;
    char *out = malloc(n + 1);
    if (!out) return NULL;
    memcpy(out, data, at);
    memcpy(out + at, to, nt);
    memcpy(out + at + nt, (const char *)data + at + nf, len - at - nf);
    out[n] = 0;
    if (out_len) *out_len = n;
    return out;
}

static char *replace(const char *s, const char *from, const char *to)
{
    return replace_n(s, strlen(s), from, to, NULL);
}

// Offset of the first body byte of a fixture.
static size_t body_offset(const unsigned char *data, size_t len)
{
    size_t at = find(data, len, "end_header\n");
    return at == SIZE_MAX ? len : at + 11;
}

static unsigned char *read_fixture(const char *name, size_t *len)
{
    char path[512];
    snprintf(path, sizeof path, FIXTURES "%s", name);
    void *data = NULL;
    rs_error err = {0};
    if (rs_file_read_all(path, 1u << 20, &data, len, &err) != RS_OK) return NULL;
    return data;
}

static rs_ply_mesh *load_fixture(const char *name)
{
    char path[512];
    snprintf(path, sizeof path, FIXTURES "%s", name);
    rs_ply_mesh *m = NULL;
    rs_error err = {0};
    if (!RS_CHECK(rs_ply_load(path, &m, &err) == RS_OK, "%s: %s", name, err.msg)) return NULL;
    return m;
}

// Parses `len` bytes expecting failure with `code` and a one-line message that contains every
// non-NULL needle.
static bool expect_fail(const void *data, size_t len, rs_result code, const char *needle1, const char *needle2)
{
    rs_ply_mesh *m = (rs_ply_mesh *)&m;  // sentinel: must be left untouched
    rs_error err = {0};
    rs_result r = parse_exact(data, len, &m, &err);
    if (r == RS_OK) {
        rs_ply_destroy(m);
        return RS_CHECK(false, "parsed, expected %s containing '%s'", rs_result_name(code), needle1 ? needle1 : "");
    }
    return RS_CHECK(r == code, "got %s (%s), expected %s", rs_result_name(r), err.msg, rs_result_name(code)) &&
           RS_CHECK(m == (rs_ply_mesh *)&m, "output written on failure") &&
           RS_CHECK(!strchr(err.msg, '\n') && err.msg[0], "message not one line: '%s'", err.msg) &&
           RS_CHECK(!needle1 || strstr(err.msg, needle1), "message '%s' lacks '%s'", err.msg, needle1) &&
           RS_CHECK(!needle2 || strstr(err.msg, needle2), "message '%s' lacks '%s'", err.msg, needle2);
}

static bool expect_fail_str(const char *s, rs_result code, const char *needle1, const char *needle2)
{
    return expect_fail(s, strlen(s), code, needle1, needle2);
}

// Variant of `base` with one substitution, expected to fail.
static bool expect_fail_edit(const char *base, const char *from, const char *to, rs_result code,
                             const char *needle1, const char *needle2)
{
    char *s = replace(base, from, to);
    if (!RS_CHECK(s, "test bug: '%s' not in base text", from)) return false;
    bool ok = expect_fail_str(s, code, needle1, needle2);
    free(s);
    return ok;
}

static bool same_floats(const float *a, const float *b, size_t n)
{
    if (!a || !b) return a == b;
    return memcmp(a, b, n * sizeof *a) == 0;
}

// Everything but the comments equal.
static bool meshes_equal(const rs_ply_mesh *a, const rs_ply_mesh *b, const char *what)
{
    bool ok = RS_CHECK(a->vertex_count == b->vertex_count, "%s: vertex counts %u vs %u", what, a->vertex_count,
                       b->vertex_count);
    ok = ok && RS_CHECK(a->tri_count == b->tri_count, "%s: triangle counts differ", what);
    if (!ok) return false;
    size_t n = a->vertex_count;
    ok = RS_CHECK(same_floats(&a->pos[0][0], &b->pos[0][0], 3 * n), "%s: positions differ", what);
    ok = ok && RS_CHECK(same_floats(a->normal ? &a->normal[0][0] : NULL, b->normal ? &b->normal[0][0] : NULL, 3 * n),
                        "%s: normals differ", what);
    ok = ok && RS_CHECK(same_floats(a->uv ? &a->uv[0][0] : NULL, b->uv ? &b->uv[0][0] : NULL, 2 * n),
                        "%s: uvs differ", what);
    ok = ok && RS_CHECK(!a->rgb == !b->rgb && (!a->rgb || memcmp(a->rgb, b->rgb, 3 * n) == 0), "%s: colours differ", what);
    ok = ok && RS_CHECK(!a->region == !b->region && (!a->region || memcmp(a->region, b->region, n) == 0),
                        "%s: regions differ", what);
    ok = ok && RS_CHECK(!a->tri == !b->tri && (!a->tri || memcmp(a->tri, b->tri, 12 * (size_t)a->tri_count) == 0),
                        "%s: triangles differ", what);
    return ok;
}

static bool is_reference_cloud(const rs_ply_mesh *m, const char *what)
{
    if (!RS_CHECK(m->vertex_count == 4 && m->normal && m->rgb, "%s: want 4 vertices with normals and colours", what))
        return false;
    bool ok = RS_CHECK(!m->uv && !m->region && !m->tri && m->tri_count == 0, "%s: unexpected uv/region/faces", what);
    for (int i = 0; i < 4; i++)
        for (int k = 0; k < 3; k++) {
            ok = ok && RS_CHECK(m->pos[i][k] == POS[i][k], "%s: pos[%d][%d] = %g, want %g", what, i, k,
                                m->pos[i][k], POS[i][k]);
            ok = ok && RS_CHECK(m->normal[i][k] == NRM[i][k], "%s: normal[%d][%d] = %g", what, i, k, m->normal[i][k]);
            ok = ok && RS_CHECK(m->rgb[i][k] == RGB[i][k], "%s: rgb[%d][%d] = %d", what, i, k, m->rgb[i][k]);
        }
    return ok;
}

// ---------------------------------------------------------------------------------------------------
// Supported variants

static void test_ascii_le_be_point_clouds_decode_equal(void)
{
    rs_ply_mesh *a = load_fixture("points_ascii.ply");
    rs_ply_mesh *le = load_fixture("points_le.ply");
    rs_ply_mesh *be = load_fixture("points_be.ply");
    if (a && le && be) {
        is_reference_cloud(a, "ascii");
        is_reference_cloud(le, "le");
        is_reference_cloud(be, "be");
        meshes_equal(a, le, "ascii vs le");
        meshes_equal(a, be, "ascii vs be");
    }
    rs_ply_destroy(a);
    rs_ply_destroy(le);
    rs_ply_destroy(be);
}

static void test_comments_are_joined_and_texture_file_found(void)
{
    rs_ply_mesh *a = load_fixture("points_ascii.ply");
    rs_ply_mesh *m = load_fixture("mesh_st.ply");
    if (a && m) {
        RS_CHECK(strcmp(a->comments, "rouge test fixture\ngenerated by make_fixtures.py") == 0, "comments '%s'",
                 a->comments);
        RS_CHECK(a->texture_file == NULL, "no TextureFile comment, got '%s'", a->texture_file);
        RS_CHECK(m->texture_file && strcmp(m->texture_file, "skin.png") == 0, "texture_file '%s'",
                 m->texture_file ? m->texture_file : "(null)");
        RS_CHECK(strstr(m->comments, "\nTextureFile skin.png"), "TextureFile comment kept: '%s'", m->comments);
    }
    rs_ply_destroy(a);
    rs_ply_destroy(m);
    // No comments at all: an empty string, never NULL.
    rs_ply_mesh *c = NULL;
    rs_error err = {0};
    char *s = replace(ASCII_CLOUD, "comment test\n", "");
    RS_REQUIRE(parse_str(s, &c, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(c->comments && c->comments[0] == 0, "comments should be empty");
    rs_ply_destroy(c);
    free(s);
}

static void test_crlf_file_decodes_like_lf(void)
{
    rs_ply_mesh *a = load_fixture("points_ascii.ply");
    rs_ply_mesh *c = load_fixture("points_crlf.ply");
    if (a && c) {
        meshes_equal(a, c, "lf vs crlf");
        RS_CHECK(strcmp(a->comments, c->comments) == 0, "comments carry no '\\r': '%s'", c->comments);
    }
    rs_ply_destroy(a);
    rs_ply_destroy(c);
    // A CRLF header in front of a binary body: the body starts right after the '\n'.
    size_t len;
    unsigned char *le = read_fixture("points_le.ply", &len);
    RS_REQUIRE(le, "points_le.ply missing");
    unsigned char *crlf = malloc(2 * len);
    if (!crlf) return (void)RS_CHECK(false, "out of memory");
    size_t n = 0, body = body_offset(le, len);
    for (size_t i = 0; i < len; i++) {
        if (i < body && le[i] == '\n') crlf[n++] = '\r';
        crlf[n++] = le[i];
    }
    rs_ply_mesh *m = NULL;
    rs_error err = {0};
    if (RS_CHECK(parse_exact(crlf, n, &m, &err) == RS_OK, "%s", err.msg)) is_reference_cloud(m, "crlf binary");
    rs_ply_destroy(m);
    free(crlf);
    free(le);
}

static void test_shuffled_properties_decode_like_ordered(void)
{
    rs_ply_mesh *a = load_fixture("points_ascii.ply");
    rs_ply_mesh *s = load_fixture("points_shuffled.ply");
    if (a && s) meshes_equal(a, s, "ordered vs shuffled");
    rs_ply_destroy(a);
    rs_ply_destroy(s);
}

static void test_points_without_normals_have_null_normals(void)
{
    rs_ply_mesh *m = load_fixture("points_no_normals.ply");
    if (!m) return;
    RS_CHECK(m->vertex_count == 3 && !m->normal && m->rgb && !m->uv && !m->tri, "fields present");
    RS_CHECK(m->pos[2][0] == -3.5f && m->rgb[2][2] == 255 && m->rgb[1][1] == 255, "values");
    rs_ply_destroy(m);
}

static void test_points_without_colours_have_null_rgb(void)
{
    rs_ply_mesh *m = load_fixture("points_no_colours.ply");
    if (!m) return;
    RS_CHECK(m->vertex_count == 3 && m->normal && !m->rgb, "fields present");
    RS_CHECK(m->pos[1][2] == -0.75f && m->normal[2][0] == 1.0f, "values");
    rs_ply_destroy(m);
}

static void test_float_colours_are_clamped_scaled_and_rounded(void)
{
    rs_ply_mesh *m = load_fixture("points_float_colours.ply");
    if (!m) return;
    // (0, .5, 1) (-.2, 1.7, .25) (.1, .9, .002): clamp(v, 0, 1) * 255 rounded; alpha ignored.
    static const uint8_t want[3][3] = {{0, 128, 255}, {0, 255, 64}, {26, 230, 1}};
    RS_REQUIRE(m->vertex_count == 3 && m->rgb, "colours present");
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++)
            RS_CHECK(m->rgb[i][k] == want[i][k], "rgb[%d][%d] = %d, want %d", i, k, m->rgb[i][k], want[i][k]);
    rs_ply_destroy(m);
}

static void test_double_positions_and_wide_integer_colours(void)
{
    rs_ply_mesh *m = load_fixture("points_double.ply");
    if (!m) return;
    RS_REQUIRE(m->vertex_count == 3 && m->rgb && !m->normal, "fields present");
    RS_CHECK(m->pos[0][0] == 0.1f && m->pos[0][1] == -2.5e-3f && m->pos[0][2] == 1e10f, "vertex 0 position");
    RS_CHECK(m->pos[1][0] == (float)(1.0 / 3.0) && m->pos[2][1] == 12345.678f, "vertex 1/2 position");
    // short -5 -> 0, ushort 300 -> 255, int 77; 0 255 256 -> 255; 255 0 -1 -> 0.
    static const uint8_t want[3][3] = {{0, 255, 77}, {0, 255, 255}, {255, 0, 0}};
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++)
            RS_CHECK(m->rgb[i][k] == want[i][k], "rgb[%d][%d] = %d, want %d", i, k, m->rgb[i][k], want[i][k]);
    rs_ply_destroy(m);
}

static void test_region_property_is_read(void)
{
    rs_ply_mesh *m = load_fixture("points_region.ply");
    if (!m) return;
    RS_CHECK(m->vertex_count == 3 && m->region && !m->rgb && !m->normal, "fields present");
    if (m->region) RS_CHECK(m->region[0] == 0 && m->region[1] == 7 && m->region[2] == 255, "region values");
    rs_ply_destroy(m);
}

static void test_diffuse_colours_and_u_v_names(void)
{
    rs_ply_mesh *m = load_fixture("points_diffuse_uv.ply");
    if (!m) return;
    RS_REQUIRE(m->vertex_count == 2 && m->rgb && m->uv, "colours and uv present");
    RS_CHECK(m->rgb[1][0] == 40 && m->rgb[1][2] == 60 && m->uv[0][0] == 0.25f && m->uv[0][1] == 0.75f, "values");
    rs_ply_destroy(m);
    // red/green/blue win over diffuse_*, s t over u v; the losers are skipped, not errors.
    m = NULL;
    rs_error err = {0};
    char *s = replace(ASCII_CLOUD, "property uchar red\n",
                      "property float s\nproperty float t\nproperty uchar diffuse_red\nproperty uchar diffuse_green\n"
                      "property uchar diffuse_blue\nproperty float u\nproperty float v\nproperty uchar red\n");
    char *t = replace(s, "0 0 0 1 2 3\n1 0 0 4 5 6\n0 1 0 7 8 9\n",
                      "0 0 0 .5 .25 9 9 9 7 7 1 2 3\n1 0 0 0 0 9 9 9 7 7 4 5 6\n0 1 0 0 0 9 9 9 7 7 7 8 9\n");
    RS_REQUIRE(parse_str(t, &m, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(m->rgb && m->rgb[0][0] == 1 && m->rgb[2][2] == 9, "red/green/blue chosen");
    RS_CHECK(m->uv && m->uv[0][0] == 0.5f && m->uv[0][1] == 0.25f, "s t chosen");
    rs_ply_destroy(m);
    free(s);
    free(t);
}

static void test_mesh_polygons_are_fan_triangulated_with_st_uv(void)
{
    rs_ply_mesh *m = load_fixture("mesh_st.ply");
    if (!m) return;
    // Faces: quad 0 1 4 3, triangle 1 2 5, pentagon 1 2 6 5 4, 2-gon 0 1 (skipped), quad 3 4 5 2.
    static const uint32_t want[8][3] = {{0, 1, 4}, {0, 4, 3}, {1, 2, 5}, {1, 2, 6},
                                        {1, 6, 5}, {1, 5, 4}, {3, 4, 5}, {3, 5, 2}};
    RS_REQUIRE(m->vertex_count == 7 && m->uv && !m->normal && !m->rgb, "vertex fields");
    RS_REQUIRE(m->tri_count == 8 && m->tri, "tri_count %u, want 8", m->tri_count);
    RS_CHECK(memcmp(m->tri, want, sizeof want) == 0, "fan order");
    RS_CHECK(m->uv[6][0] == 0.75f && m->uv[6][1] == 0.5f && m->uv[1][0] == 0.25f, "s t values");
    rs_ply_destroy(m);
}

static void test_mesh_with_texture_u_v_any_element_order_and_unknown_lists(void)
{
    // material and face come before vertex, edge after; vertex has a `weights` list (general path),
    // face has a texcoord list and a flags byte; indices are `vertex_index` uint8/uint32.
    rs_ply_mesh *m = load_fixture("mesh_texture_uv.ply");
    if (!m) return;
    static const uint32_t want[3][3] = {{0, 1, 2}, {0, 2, 3}, {2, 3, 0}};
    static const float uv[4][2] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
    RS_REQUIRE(m->vertex_count == 4 && m->uv && m->tri_count == 3, "counts: %u vertices, %u triangles",
               m->vertex_count, m->tri_count);
    RS_CHECK(memcmp(m->tri, want, sizeof want) == 0, "triangles");
    RS_CHECK(memcmp(m->uv, uv, sizeof uv) == 0, "texture_u texture_v");
    RS_CHECK(m->pos[2][0] == 1.0f && m->pos[2][1] == 1.0f && m->pos[3][1] == 1.0f, "positions");
    rs_ply_destroy(m);
}

// Writes v as type `t` (PLY name) in the given byte order; returns bytes written.
static size_t put(unsigned char *p, const char *t, double v, bool big)
{
    static const struct {
        const char *name;
        size_t size;
        bool is_float;
    } types[] = {{"char", 1, false},   {"uchar", 1, false},  {"short", 2, false},  {"ushort", 2, false},
                 {"int", 4, false},    {"uint", 4, false},   {"float", 4, true},   {"double", 8, true},
                 {"int8", 1, false},   {"uint8", 1, false},  {"int16", 2, false},  {"uint16", 2, false},
                 {"int32", 4, false},  {"uint32", 4, false}, {"float32", 4, true}, {"float64", 8, true}};
    size_t n = 0;
    bool is_float = false;
    for (size_t i = 0; i < RS_COUNT_OF(types); i++)
        if (strcmp(t, types[i].name) == 0) n = types[i].size, is_float = types[i].is_float;
    uint64_t bits;
    if (is_float && n == 4) {
        float f = (float)v;
        uint32_t u;
        memcpy(&u, &f, 4);
        bits = u;
    } else if (is_float) {
        memcpy(&bits, &v, 8);
    } else {
        bits = (uint64_t)(int64_t)v;
    }
    for (size_t k = 0; k < n; k++) p[big ? n - 1 - k : k] = (unsigned char)(bits >> (8 * k));
    return n;
}

static void test_every_property_type_decodes_in_both_byte_orders(void)
{
    static const char *types[] = {"char",  "uchar", "short",  "ushort", "int",   "uint",    "float",   "double",
                                  "int8",  "uint8", "int16",  "uint16", "int32", "uint32",  "float32", "float64"};
    for (size_t ti = 0; ti < RS_COUNT_OF(types); ti++) {
        const char *t = types[ti];
        bool is_signed = t[0] != 'u', is_int = !strstr(t, "float") && strcmp(t, "double") != 0;
        for (int big = 0; big < 2; big++) {
            unsigned char buf[1024];
            int h = snprintf((char *)buf, sizeof buf,
                             "ply\nformat binary_%s_endian 1.0\nelement vertex 3\nproperty %s x\nproperty %s y\n"
                             "property %s z\nelement face 1\nproperty list %s %s vertex_indices\nend_header\n",
                             big ? "big" : "little", t, t, t, is_int ? t : "uchar", is_int ? t : "int");
            size_t n = (size_t)h;
            for (int i = 0; i < 3; i++) {
                n += put(buf + n, t, is_signed ? -(i + 1) : i + 1, big);
                n += put(buf + n, t, 2 * (i + 1), big);
                n += put(buf + n, t, 100 - i, big);
            }
            n += put(buf + n, is_int ? t : "uchar", 3, big);
            for (int i = 0; i < 3; i++) n += put(buf + n, is_int ? t : "int", 2 - i, big);
            rs_ply_mesh *m = NULL;
            rs_error err = {0};
            if (!RS_CHECK(parse_exact(buf, n, &m, &err) == RS_OK, "%s %s: %s", t, big ? "BE" : "LE", err.msg)) return;
            for (int i = 0; i < 3; i++)
                RS_CHECK(m->pos[i][0] == (is_signed ? -(i + 1) : i + 1) && m->pos[i][1] == 2 * (i + 1) &&
                             m->pos[i][2] == 100 - i,
                         "%s %s: vertex %d = %g %g %g", t, big ? "BE" : "LE", i, m->pos[i][0], m->pos[i][1],
                         m->pos[i][2]);
            RS_CHECK(m->tri_count == 1 && m->tri[0][0] == 2 && m->tri[0][1] == 1 && m->tri[0][2] == 0,
                     "%s %s: face", t, big ? "BE" : "LE");
            rs_ply_destroy(m);
        }
    }
}

static void test_big_polygon_grows_triangle_array(void)
{
    // One 1000-gon (ushort count): 998 triangles from a single face, past the first allocation.
    enum { N = 1000 };
    static unsigned char buf[256 + N * 12 + N * 4];
    size_t n = (size_t)snprintf((char *)buf, 256,
                                "ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\n"
                                "property float y\nproperty float z\nelement face 1\n"
                                "property list ushort uint vertex_indices\nend_header\n",
                                N);
    for (int i = 0; i < N; i++) {
        n += put(buf + n, "float", cos(i * 0.00628), false);
        n += put(buf + n, "float", sin(i * 0.00628), false);
        n += put(buf + n, "float", 0, false);
    }
    n += put(buf + n, "ushort", N, false);
    for (int i = 0; i < N; i++) n += put(buf + n, "uint", i, false);
    rs_ply_mesh *m = NULL;
    rs_error err = {0};
    RS_REQUIRE(parse_exact(buf, n, &m, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(m->tri_count == N - 2, "tri_count %u", m->tri_count);
    bool fan = true;
    for (uint32_t i = 0; i < m->tri_count; i++)
        fan = fan && m->tri[i][0] == 0 && m->tri[i][1] == i + 1 && m->tri[i][2] == i + 2;
    RS_CHECK(fan, "fan order");
    rs_ply_destroy(m);
}

static void test_unknown_elements_and_properties_are_skipped_in_ascii(void)
{
    char *s = replace(ASCII_MESH, "element face 2\nproperty list uchar int vertex_indices\n",
                      "element face 2\nproperty uchar flags\nproperty list uchar int vertex_indices\n"
                      "property list uchar float texcoord\nelement edge 1\nproperty list int int chain\n"
                      "property double weight\n");
    char *t = replace(s, "3 0 1 2\n3 2 1 0\n", "9 3 0 1 2 6 0 0 1 0 0 1\n0 3 2 1 0 0\n3 -1 -2 -3 1e300\n");
    free(s);
    s = replace(t, "property float z\n", "property float z\nproperty list uchar uchar junk\nproperty float alpha\n");
    free(t);
    t = replace(s, "0 0 0\n1 0 0\n0 1 0\n", "0 0 0 2 7 7 0.5\n1 0 0 0 1\n0 1 0 1 255 -9\n");
    rs_ply_mesh *m = NULL;
    rs_error err = {0};
    if (RS_CHECK(parse_str(t, &m, &err) == RS_OK, "%s", err.msg)) {
        RS_CHECK(m->vertex_count == 3 && m->tri_count == 2 && m->tri[1][0] == 2 && m->pos[2][1] == 1.0f, "values");
        rs_ply_destroy(m);
    }
    free(s);
    free(t);
}

// ---------------------------------------------------------------------------------------------------
// Malformed input

static void test_truncated_binary_fails_at_every_prefix(void)
{
    static const char *names[] = {"points_le.ply", "points_be.ply", "points_shuffled.ply", "mesh_texture_uv.ply",
                                  "points_double.ply"};
    for (size_t f = 0; f < RS_COUNT_OF(names); f++) {
        size_t len;
        unsigned char *data = read_fixture(names[f], &len);
        if (!RS_CHECK(data, "%s missing", names[f])) return;
        for (size_t n = 0; n < len; n++) {
            rs_ply_mesh *m = NULL;
            rs_error err = {0};
            rs_result r = parse_exact(data, n, &m, &err);
            if (!RS_CHECK(r == RS_ERR_FORMAT || r == RS_ERR_LIMIT, "%s cut at %zu: %s (%s)", names[f], n,
                          rs_result_name(r), err.msg)) {
                rs_ply_destroy(m);
                break;
            }
            RS_CHECK(!strchr(err.msg, '\n') && (strstr(err.msg, "(line ") || strstr(err.msg, "(byte ")),
                     "%s cut at %zu: message '%s'", names[f], n, err.msg);
        }
        free(data);
    }
}

static void test_truncated_ascii_never_crashes(void)
{
    static const char *names[] = {"points_ascii.ply", "mesh_st.ply", "points_crlf.ply"};
    for (size_t f = 0; f < RS_COUNT_OF(names); f++) {
        size_t len;
        unsigned char *data = read_fixture(names[f], &len);
        if (!RS_CHECK(data, "%s missing", names[f])) return;
        rs_ply_mesh *full = NULL;
        rs_error err = {0};
        RS_CHECK(parse_exact(data, len, &full, &err) == RS_OK, "%s: %s", names[f], err.msg);
        size_t fails = 0;
        for (size_t n = 0; n < len; n++) {
            rs_ply_mesh *m = NULL;
            if (parse_exact(data, n, &m, &err) != RS_OK) {
                fails++;
                continue;
            }
            // A cut inside the last number can still parse; everything else must be whole.
            RS_CHECK(full && m->vertex_count == full->vertex_count && m->tri_count == full->tri_count,
                     "%s cut at %zu parsed with other counts", names[f], n);
            rs_ply_destroy(m);
        }
        RS_CHECK(fails + 8 >= len, "%s: only %zu of %zu prefixes failed", names[f], fails, len);
        rs_ply_destroy(full);
        free(data);
    }
}

static void test_huge_element_counts_fail_before_allocating(void)
{
    size_t len;
    unsigned char *le = read_fixture("points_le.ply", &len);
    RS_REQUIRE(le, "points_le.ply missing");
    size_t n;
    char *s = replace_n(le, len, "element vertex 4\n", "element vertex 4000000000\n", &n);
    RS_REQUIRE(s, "test bug");
    // 4e9 records of 27 bytes would be 108 GB: refused from the count alone.
    expect_fail(s, n, RS_ERR_FORMAT, "element vertex: 4000000000 records", "(byte ");
    free(s);
    free(le);
    expect_fail_edit(ASCII_CLOUD, "element vertex 3", "element vertex 4000000000", RS_ERR_FORMAT,
                     "element vertex: 4000000000 records", "(line ");
    expect_fail_edit(ASCII_CLOUD, "element vertex 3", "element vertex 5000000000", RS_ERR_LIMIT, "exceeds", "(line 4)");
    expect_fail_edit(ASCII_MESH, "element face 2", "element face 4000000000", RS_ERR_FORMAT, "element face", NULL);
    expect_fail_edit(ASCII_CLOUD, "element vertex 3", "element vertex 99999999999999999999999", RS_ERR_LIMIT,
                     "exceeds", NULL);
    // An unknown element with a huge count is checked the same way.
    expect_fail_edit(ASCII_CLOUD, "end_header", "element junk 4000000000\nproperty uchar a\nend_header",
                     RS_ERR_FORMAT, "element junk", NULL);
    // A 3000-character element name is cut in the message, which still ends with the location.
    char line[3100] = "element ";
    memset(line + 8, 'e', 3000);
    strcpy(line + 3008, " 4000000000\nproperty uchar a\nend_header");
    char *t = replace(ASCII_CLOUD, "end_header", line);
    RS_REQUIRE(t, "test bug");
    rs_ply_mesh *m = NULL;
    rs_error err = {0};
    RS_CHECK(parse_str(t, &m, &err) == RS_ERR_FORMAT, "long name: %s", err.msg);
    RS_CHECK(strlen(err.msg) < sizeof err.msg - 1 && strstr(err.msg, "(line 16)"), "location kept: %s", err.msg);
    free(t);
}

static void test_header_errors_name_the_problem_and_line(void)
{
    expect_fail_str("", RS_ERR_FORMAT, "not a PLY file", "(line 1)");
    expect_fail_edit(ASCII_CLOUD, "ply\n", "PLY\n", RS_ERR_FORMAT, "not a PLY file", "(line 1)");
    // (Before the first element, free text is taken as a comment: test_lenient_inputs_load_with_a_warning.)
    expect_fail_edit(ASCII_CLOUD, "property float y\n", "commentary test\n", RS_ERR_FORMAT,
                     "unknown header keyword 'commentary'", "(line 6)");
    expect_fail_edit(ASCII_CLOUD, "end_header\n0 0 0 1 2 3\n1 0 0 4 5 6\n0 1 0 7 8 9\n", "", RS_ERR_FORMAT,
                     "missing end_header", NULL);
    expect_fail_edit(ASCII_CLOUD, "end_header\n", "end_header extra\n", RS_ERR_FORMAT, "after end_header", NULL);
    expect_fail_edit(ASCII_CLOUD, "float y", "float16 y", RS_ERR_FORMAT, "unknown type 'float16'", "(line 6)");
    expect_fail_edit(ASCII_CLOUD, "float y", "list uchar vec3 y", RS_ERR_FORMAT, "unknown type 'vec3'", NULL);
    expect_fail_edit(ASCII_CLOUD, "float y", "list float int y", RS_ERR_FORMAT, "count type", NULL);
    expect_fail_edit(ASCII_CLOUD, "ascii 1.0", "ascii 2.0", RS_ERR_FORMAT, "unsupported PLY version", "(line 2)");
    expect_fail_edit(ASCII_CLOUD, "ascii 1.0", "binary_middle_endian 1.0", RS_ERR_FORMAT, "unknown format", NULL);
    expect_fail_edit(ASCII_CLOUD, "format ascii 1.0\n", "", RS_ERR_FORMAT, "no format line", NULL);
    expect_fail_edit(ASCII_CLOUD, "comment test\n", "format ascii 1.0\n", RS_ERR_FORMAT, "second format", NULL);
    expect_fail_edit(ASCII_CLOUD, "comment test\n", "property float w\n", RS_ERR_FORMAT, "property before any element",
                     "(line 3)");
    expect_fail_edit(ASCII_CLOUD, "end_header", "element vertex 1\nproperty float x\nend_header", RS_ERR_FORMAT,
                     "duplicate element 'vertex'", NULL);
    expect_fail_edit(ASCII_CLOUD, "property float y\n", "property float x\n", RS_ERR_FORMAT,
                     "duplicate property 'x'", NULL);
    expect_fail_edit(ASCII_CLOUD, "element vertex 3", "element point 3", RS_ERR_FORMAT, "no vertex element", NULL);
    expect_fail_edit(ASCII_CLOUD, "element vertex 3", "element vertex", RS_ERR_FORMAT, "element line", NULL);
    expect_fail_edit(ASCII_CLOUD, "element vertex 3", "element vertex -3", RS_ERR_FORMAT, "not a number", NULL);
    expect_fail_edit(ASCII_CLOUD, "property float z\n", "", RS_ERR_FORMAT, "incomplete position", "(line 4)");
    expect_fail_edit(ASCII_CLOUD, "property float z\n", "property float z\nproperty float nx\n", RS_ERR_FORMAT,
                     "incomplete normal", NULL);
    expect_fail_edit(ASCII_CLOUD, "property uchar blue\n", "", RS_ERR_FORMAT, "incomplete colour", NULL);
    expect_fail_edit(ASCII_CLOUD, "property float z\n", "property float z\nproperty float texture_u\n", RS_ERR_FORMAT,
                     "incomplete texture coordinate", NULL);
    expect_fail_edit(ASCII_CLOUD, "property float z\n", "property float z\nproperty float region\n", RS_ERR_FORMAT,
                     "region must have an integer type", NULL);
    expect_fail_edit(ASCII_CLOUD, "property float z\n", "property list uchar float z\n", RS_ERR_FORMAT,
                     "must not be a list", NULL);
    expect_fail_edit(ASCII_MESH, "property list uchar int vertex_indices", "property int vertex_indices",
                     RS_ERR_FORMAT, "must be a list", NULL);
    expect_fail_edit(ASCII_MESH, "property list uchar int vertex_indices", "property list uchar float vertex_indices",
                     RS_ERR_FORMAT, "index type", NULL);
    expect_fail_edit(ASCII_MESH, "property list uchar int vertex_indices", "property list uchar int corners",
                     RS_ERR_FORMAT, "no vertex_indices", NULL);
    expect_fail_edit(ASCII_CLOUD, "comment test", "comment te\001st", RS_ERR_FORMAT, "control byte 0x01", NULL);
    expect_fail_edit(ASCII_CLOUD, "comment test", "comment te\rst", RS_ERR_FORMAT, "control byte 0x0d", NULL);

    // A NUL inside the header (cannot go through C strings).
    char nul[sizeof ASCII_CLOUD];
    memcpy(nul, ASCII_CLOUD, sizeof nul);
    nul[20] = 0;
    expect_fail(nul, sizeof nul - 1, RS_ERR_FORMAT, "control byte 0x00", NULL);

    // Size limits: a 5000-byte comment line; a header of 70 000 bytes of comments.
    size_t big = 70000;
    char *s = malloc(big + 1024);
    if (!s) return (void)RS_CHECK(false, "out of memory");
    memcpy(s, "ply\ncomment ", 12);
    memset(s + 12, 'a', 5000);
    strcpy(s + 5012, ASCII_CLOUD + 3);
    expect_fail_str(s, RS_ERR_LIMIT, "header line longer than", "(line 2)");
    size_t n = 4;
    memcpy(s, "ply\n", 4);
    while (n < big) {
        memcpy(s + n, "comment 0123456789012345678901234567890123456789\n", 49);
        n += 49;
    }
    strcpy(s + n, ASCII_CLOUD + 4);
    expect_fail_str(s, RS_ERR_LIMIT, "header longer than 65536 bytes", NULL);
    free(s);
}

static void test_face_index_out_of_range_names_the_face(void)
{
    expect_fail_edit(ASCII_MESH, "3 2 1 0\n", "3 2 3 0\n", RS_ERR_FORMAT, "face 1: vertex index 3 out of range",
                     "(line 14)");
    expect_fail_edit(ASCII_MESH, "3 2 1 0\n", "3 2 -1 0\n", RS_ERR_FORMAT, "face 1: vertex index -1", NULL);
    // Also in a 2-gon that would be skipped: every index is validated.
    expect_fail_edit(ASCII_MESH, "3 2 1 0\n", "2 2 7\n", RS_ERR_FORMAT, "face 1: vertex index 7", NULL);
    // Binary: the message gives the byte of the bad index.
    size_t len;
    unsigned char *d = read_fixture("mesh_texture_uv.ply", &len);
    RS_REQUIRE(d, "mesh_texture_uv.ply missing");
    size_t body = body_offset(d, len);
    // material (3 bytes), then face 0: count byte, indices 0 1 2 3 as uint32.
    size_t at = body + 3 + 1 + 2 * 4;
    d[at] = 9;
    char want[64];
    snprintf(want, sizeof want, "(byte %zu)", at);
    expect_fail(d, len, RS_ERR_FORMAT, "face 0: vertex index 9 out of range (4 vertices)", want);
    d[at] = 0xff, d[at + 1] = 0xff, d[at + 2] = 0xff, d[at + 3] = 0xff;  // uint32 4294967295
    expect_fail(d, len, RS_ERR_FORMAT, "vertex index 4294967295", NULL);
    free(d);
}

static void test_bad_list_counts_fail(void)
{
    expect_fail_edit(ASCII_MESH, "3 2 1 0\n", "-3 2 1 0\n", RS_ERR_FORMAT, "face 1", "-3 is out of range for uchar");
    char *s = replace(ASCII_MESH, "list uchar int", "list int int");
    expect_fail_edit(s, "3 2 1 0\n", "-3 2 1 0\n", RS_ERR_FORMAT, "face 1: property vertex_indices: list count -3",
                     "negative");
    free(s);
    expect_fail_edit(ASCII_MESH, "3 2 1 0\n", "200 2 1 0\n", RS_ERR_FORMAT, "face 1", "exceeds the data left");
    expect_fail_edit(ASCII_MESH, "3 2 1 0\n", "3 2 1\n", RS_ERR_FORMAT, "face 1: too few values", "(line 14)");
    // Binary: a signed count of -1, and a uint count of 4e9, in the face and in an unknown list.
    size_t len;
    unsigned char *d = read_fixture("mesh_texture_uv.ply", &len);
    RS_REQUIRE(d, "mesh_texture_uv.ply missing");
    size_t body = body_offset(d, len);
    d[body + 3] = 200;  // face 0 claims 200 uint32 indices: more than the bytes left
    expect_fail(d, len, RS_ERR_FORMAT, "face 0: property vertex_index: list of 200 items", NULL);
    d[body + 3] = 4;
    d[body + 3 + 17] = 250;  // face 0 texcoord list: 250 floats
    expect_fail(d, len, RS_ERR_FORMAT, "face 0: property texcoord", "does not fit");
    free(d);
    unsigned char buf[512];
    int h = snprintf((char *)buf, sizeof buf,
                     "ply\nformat binary_big_endian 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                     "property float z\nelement face 1\nproperty list %s int vertex_indices\nend_header\n",
                     "char");
    size_t n = (size_t)h + 12;
    memset(buf + h, 0, 12);
    buf[n] = 0xff;  // char -1
    memset(buf + n + 1, 0, 12);
    expect_fail(buf, n + 13, RS_ERR_FORMAT, "negative list count -1", NULL);
    h = snprintf((char *)buf, sizeof buf,
                 "ply\nformat binary_big_endian 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                 "property float z\nelement face 1\nproperty list %s int vertex_indices\nend_header\n",
                 "uint");
    n = (size_t)h + 12;
    memset(buf + h, 0, 12);
    memcpy(buf + n, "\xee\x6b\x28\x00", 4);  // 4000000000
    memset(buf + n + 4, 0, 12);
    expect_fail(buf, n + 16, RS_ERR_FORMAT, "list of 4000000000 items", NULL);
}

static void test_non_finite_positions_name_the_vertex(void)
{
    expect_fail_edit(ASCII_CLOUD, "0 1 0 7 8 9", "0 nan 0 7 8 9", RS_ERR_FORMAT, "vertex 2: position y is NaN",
                     "(line 14)");
    expect_fail_edit(ASCII_CLOUD, "1 0 0 4 5 6", "1 0 -inf 4 5 6", RS_ERR_FORMAT, "vertex 1: position z is infinite",
                     "(line 13)");
    expect_fail_edit(ASCII_CLOUD, "1 0 0 4 5 6", "1e39 0 0 4 5 6", RS_ERR_FORMAT, "vertex 1: position x", NULL);
    size_t len;
    unsigned char *d = read_fixture("points_le.ply", &len);
    RS_REQUIRE(d, "points_le.ply missing");
    size_t rec = len - 27;  // last vertex: x is its first float
    memcpy(d + rec, "\x00\x00\xc0\x7f", 4);
    char want[64];
    snprintf(want, sizeof want, "(byte %zu)", rec);
    expect_fail(d, len, RS_ERR_FORMAT, "vertex 3: position x is NaN", want);
    free(d);
    // A double beyond float range (binary general path: the vertex has a list property).
    unsigned char buf[512];
    size_t n = (size_t)snprintf((char *)buf, sizeof buf,
                                "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty double x\n"
                                "property list uchar uchar junk\nproperty double y\nproperty double z\nend_header\n");
    n += put(buf + n, "double", 1.0, false);
    buf[n++] = 0;
    n += put(buf + n, "double", 1e300, false);
    n += put(buf + n, "double", 1.0, false);
    expect_fail(buf, n, RS_ERR_FORMAT, "vertex 0: position y is infinite or beyond float range", NULL);
}

static void test_ascii_value_errors_name_the_line(void)
{
    // (Longer numbers: the body must still hold 3 records of 6 values by byte count.)
    expect_fail_edit(ASCII_CLOUD, "1 0 0 4 5 6", "1.00 0.00 0 4 5", RS_ERR_FORMAT,
                     "vertex 1: too few values, property blue", "(line 13)");
    expect_fail_edit(ASCII_CLOUD, "1 0 0 4 5 6", "1 0 0 4 5 6 7", RS_ERR_FORMAT, "vertex 1: more values", "(line 13)");
    expect_fail_edit(ASCII_CLOUD, "1 0 0 4 5 6\n0 1 0 7 8 9\n", "1.0000 0.0000 0.0000 4 5 6\n", RS_ERR_FORMAT,
                     "vertex 2: data ends", NULL);
    // Too few bytes for the declared records at all: caught before allocating.
    expect_fail_edit(ASCII_CLOUD, "0 1 0 7 8 9\n", "", RS_ERR_FORMAT, "element vertex: 3 records", "(line 12)");
    expect_fail_edit(ASCII_CLOUD, "1 0 0 4 5 6", "1 0 zero 4 5 6", RS_ERR_FORMAT, "vertex 1: property z: 'zero' is not a number",
                     "(line 13)");
    expect_fail_edit(ASCII_CLOUD, "1 0 0 4 5 6", "1 0 0 4.5 5 6", RS_ERR_FORMAT, "'4.5' is not an integer", NULL);
    expect_fail_edit(ASCII_CLOUD, "1 0 0 4 5 6", "1 0 0 4 300 6", RS_ERR_FORMAT, "300 is out of range for uchar", NULL);
    expect_fail_edit(ASCII_CLOUD, "1 0 0 4 5 6", "1 0 0 4 5 99999999999999999999", RS_ERR_FORMAT, "out of range", NULL);
    expect_fail_edit(ASCII_CLOUD, "1 0 0 4 5 6", "1 0 0\x1b[31m 4 5 6", RS_ERR_FORMAT, "'0?[31m' is not", NULL);
    char longtok[300] = "1 0 ";
    memset(longtok + 4, '1', 200);
    strcpy(longtok + 204, " 4 5 6");
    expect_fail_edit(ASCII_CLOUD, "1 0 0 4 5 6", longtok, RS_ERR_FORMAT, "longer than", NULL);
    // Blank lines between records are fine; records split across lines are not.
    rs_ply_mesh *m = NULL;
    rs_error err = {0};
    char *s = replace(ASCII_CLOUD, "1 0 0 4 5 6\n", "\n  \n1 0 0 4 5 6\n\n");
    RS_CHECK(parse_str(s, &m, &err) == RS_OK, "blank lines: %s", err.msg);
    rs_ply_destroy(m);
    free(s);
    expect_fail_edit(ASCII_CLOUD, "1 0 0 4 5 6", "1 0 0\n4 5 6", RS_ERR_FORMAT, "too few values", "(line 13)");
}

static void test_region_over_255_fails(void)
{
    char *s = replace(ASCII_CLOUD, "property uchar blue\n", "property uchar blue\nproperty ushort region\n");
    char *t = replace(s, "0 1 0 7 8 9", "0 1 0 7 8 9 256");
    free(s);
    s = replace(t, "1 0 0 4 5 6", "1 0 0 4 5 6 3");
    free(t);
    t = replace(s, "0 0 0 1 2 3", "0 0 0 1 2 3 0");
    expect_fail_str(t, RS_ERR_FORMAT, "vertex 2: region 256 is outside 0..255", "(line 15)");
    free(s);
    free(t);
}

static void test_bad_fixtures_fail_cleanly(void)
{
    DIR *dir = opendir(FIXTURES);
    RS_REQUIRE(dir, "cannot list " FIXTURES);
    int seen = 0;
    struct dirent *ent;
    while ((ent = readdir(dir))) {
        const char *name = ent->d_name;
        size_t n = strlen(name);
        // bad_*.ply: malformed seeds; crash-*: inputs the fuzzer once crashed on.
        if (!(strncmp(name, "bad_", 4) == 0 && n > 4 && strcmp(name + n - 4, ".ply") == 0) &&
            strncmp(name, "crash-", 6) != 0)
            continue;
        char path[512];
        snprintf(path, sizeof path, FIXTURES "%s", name);
        rs_ply_mesh *m = NULL;
        rs_error err = {0};
        rs_result r = rs_ply_load(path, &m, &err);
        RS_CHECK(r == RS_ERR_FORMAT || r == RS_ERR_LIMIT, "%s: %s", name, r == RS_OK ? "parsed" : err.msg);
        RS_CHECK(r == RS_OK || strncmp(err.msg, path, strlen(path)) == 0, "%s: message lacks the path: %s", name,
                 err.msg);
        if (r == RS_OK) rs_ply_destroy(m);
        seen++;
    }
    closedir(dir);
    RS_CHECK(seen >= 4, "only %d bad fixtures found", seen);
}

static void test_load_reports_missing_file(void)
{
    rs_ply_mesh *m = NULL;
    rs_error err = {0};
    RS_CHECK(rs_ply_load(FIXTURES "no_such_file.ply", &m, &err) == RS_ERR_IO && m == NULL, "missing file");
    RS_CHECK(strstr(err.msg, "no_such_file.ply"), "message names the file: %s", err.msg);
    RS_CHECK(rs_ply_load(FIXTURES, &m, &err) == RS_ERR_IO, "a directory is refused");
    rs_ply_destroy(NULL);
}

// ---------------------------------------------------------------------------------------------------
// Shared real data (skipped when absent)

static rs_ply_mesh *load_shared(const char *rel)
{
    const char *path = rs_test_shared_path(rel);
    if (!path) {
        rs_test_skip("%s not present", rel);
        return NULL;
    }
    rs_ply_mesh *m = NULL;
    rs_error err = {0};
    if (!RS_CHECK(rs_ply_load(path, &m, &err) == RS_OK, "%s", err.msg)) return NULL;
    return m;
}

static bool all_in_box(const rs_ply_mesh *m, float lim)
{
    for (uint32_t i = 0; i < m->vertex_count; i++)
        for (int k = 0; k < 3; k++)
            if (!(fabsf(m->pos[i][k]) < lim)) return false;
    return true;
}

static void test_shared_head_points_20k_ascii(void)
{
    rs_ply_mesh *m = load_shared("leeperrysmith/head_points_20k_ascii.ply");
    if (!m) return;
    RS_CHECK(m->vertex_count == 20000 && m->normal && m->rgb && !m->uv && !m->tri, "20000 points with normals+colours");
    RS_CHECK(strstr(m->comments, "Lee Perry-Smith") != NULL, "attribution kept in comments");
    RS_CHECK(all_in_box(m, 100) && fabsf(m->normal[123][0] * m->normal[123][0] + m->normal[123][1] * m->normal[123][1] +
                                         m->normal[123][2] * m->normal[123][2] - 1) < 0.01f,
             "plausible values");
    rs_ply_destroy(m);
}

static void test_shared_head_mesh(void)
{
    rs_ply_mesh *m = load_shared("leeperrysmith/head_mesh.ply");
    if (!m) return;
    RS_CHECK(m->vertex_count == 9279 && m->tri_count == 17684 && m->uv && m->normal && !m->rgb,
             "%u vertices, %u triangles", m->vertex_count, m->tri_count);
    RS_CHECK(m->texture_file && strcmp(m->texture_file, "color.png") == 0, "TextureFile color.png");
    rs_ply_destroy(m);
}

static void test_shared_demosthenes_points_100k(void)
{
    rs_ply_mesh *m = load_shared("demosthenes/demosthenes_points_100k.ply");
    if (!m) return;
    RS_CHECK(m->vertex_count == 100000 && m->normal && !m->rgb && !m->tri, "100000 points, normals, no colours");
    rs_ply_destroy(m);
}

static void test_shared_head_points_600k(void)
{
    rs_ply_mesh *m = load_shared("leeperrysmith/head_points_600k.ply");
    if (!m) return;
    RS_CHECK(m->vertex_count == 600000 && m->normal && m->rgb && all_in_box(m, 100), "600000 points");
    rs_ply_destroy(m);
}

// What mainstream readers accept and is unambiguous loads with a warning; truly malformed still fails.
static void test_lenient_inputs_load_with_a_warning(void)
{
    struct { const char *file, *warning; uint32_t tris; } ok[] = {
        {"tests/fixtures/ply/lenient_bom.ply", "byte-order mark", 0},
        {"tests/fixtures/ply/lenient_created_by.ply", "without 'comment'", 2},
        {"tests/fixtures/ply/lenient_face_extras.ply", "does not declare", 2},
    };
    for (size_t i = 0; i < RS_COUNT_OF(ok); i++) {
        rs_ply_mesh *m = NULL;
        rs_error err = {0};
        rs_result r = rs_ply_load(ok[i].file, &m, &err);
        RS_CHECK(r == RS_OK, "%s: %s", ok[i].file, err.msg);
        if (r != RS_OK) continue;
        RS_CHECK(m->vertex_count == 4 && m->tri_count == ok[i].tris, "%s: %u vertices, %u triangles", ok[i].file,
                 m->vertex_count, m->tri_count);
        RS_CHECK(strstr(m->warnings, ok[i].warning) != NULL, "%s: warnings '%s'", ok[i].file, m->warnings);
        if (i == 1) RS_CHECK(strstr(m->comments, "Created by Blender 2.47") != NULL, "comments '%s'", m->comments);
        rs_ply_destroy(m);
    }
    rs_ply_mesh *m = NULL;
    rs_error err = {0};
    RS_CHECK(rs_ply_load("tests/fixtures/bad/ply_vertex_extra_values.ply", &m, &err) != RS_OK &&
                 strstr(err.msg, "vertex 0: more values than the header declares"),
             "a vertex with an undeclared value: %s", m ? "accepted" : err.msg);
    rs_ply_destroy(m);
    // After the first element an unknown keyword is still an error (a typo would drop a property).
    const char *typo = "ply\nformat ascii 1.0\nelement vertex 1\npropety float x\nend_header\n0\n";
    RS_CHECK(rs_ply_load_memory(typo, strlen(typo), &m, &err) != RS_OK && strstr(err.msg, "unknown header keyword"),
             "typo: %s", err.msg);
}

int main(int argc, char **argv)
{
    rs_test_init(argc, argv);
    RS_RUN(test_ascii_le_be_point_clouds_decode_equal);
    RS_RUN(test_comments_are_joined_and_texture_file_found);
    RS_RUN(test_crlf_file_decodes_like_lf);
    RS_RUN(test_shuffled_properties_decode_like_ordered);
    RS_RUN(test_points_without_normals_have_null_normals);
    RS_RUN(test_points_without_colours_have_null_rgb);
    RS_RUN(test_float_colours_are_clamped_scaled_and_rounded);
    RS_RUN(test_double_positions_and_wide_integer_colours);
    RS_RUN(test_region_property_is_read);
    RS_RUN(test_diffuse_colours_and_u_v_names);
    RS_RUN(test_mesh_polygons_are_fan_triangulated_with_st_uv);
    RS_RUN(test_mesh_with_texture_u_v_any_element_order_and_unknown_lists);
    RS_RUN(test_every_property_type_decodes_in_both_byte_orders);
    RS_RUN(test_big_polygon_grows_triangle_array);
    RS_RUN(test_unknown_elements_and_properties_are_skipped_in_ascii);
    RS_RUN(test_truncated_binary_fails_at_every_prefix);
    RS_RUN(test_truncated_ascii_never_crashes);
    RS_RUN(test_huge_element_counts_fail_before_allocating);
    RS_RUN(test_header_errors_name_the_problem_and_line);
    RS_RUN(test_face_index_out_of_range_names_the_face);
    RS_RUN(test_bad_list_counts_fail);
    RS_RUN(test_non_finite_positions_name_the_vertex);
    RS_RUN(test_ascii_value_errors_name_the_line);
    RS_RUN(test_region_over_255_fails);
    RS_RUN(test_bad_fixtures_fail_cleanly);
    RS_RUN(test_load_reports_missing_file);
    RS_RUN(test_shared_head_points_20k_ascii);
    RS_RUN(test_shared_head_mesh);
    RS_RUN(test_shared_demosthenes_points_100k);
    RS_RUN(test_shared_head_points_600k);
    RS_RUN(test_lenient_inputs_load_with_a_warning);
    return rs_test_finish();
}
