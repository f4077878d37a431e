// ply.c — see ply.h.
//
// Two steps. The header (at most PLY_MAX_HEADER bytes) is copied, NUL-terminated, and parsed into a
// table of elements and properties; each property gets the role it plays in the mesh (x, nx, red, s,
// region, face indices...) or none. The body is then read element by element through a cursor that
// never passes `len`: binary elements without list properties take a fast path with per-property byte
// offsets; anything else is read property by property with a bounds check before each read. ASCII
// bodies are read one record per line, each number parsed by strtod/strtoll from a bounded,
// NUL-terminated copy (the input buffer is not NUL-terminated).
#define _POSIX_C_SOURCE 200809L
#include "pack/ply.h"

#include <assert.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PLY_MAX_HEADER (64u * 1024u)  // bytes, end_header line included
#define PLY_MAX_LINE 4096u            // bytes per header line
#define PLY_MAX_ELEMENTS 64u
#define PLY_MAX_PROPS 512u            // over all elements
#define PLY_MAX_TOKEN 127u            // characters in one ASCII number

typedef enum ply_format { PLY_ASCII, PLY_LE, PLY_BE } ply_format;

typedef enum ply_type { PLY_NONE, PLY_I8, PLY_U8, PLY_I16, PLY_U16, PLY_I32, PLY_U32, PLY_F32, PLY_F64 } ply_type;

static const struct {
    const char *name;
    ply_type type;
} type_names[] = {
    {"char", PLY_I8},     {"uchar", PLY_U8},     {"short", PLY_I16},    {"ushort", PLY_U16},
    {"int", PLY_I32},     {"uint", PLY_U32},     {"float", PLY_F32},    {"double", PLY_F64},
    {"int8", PLY_I8},     {"uint8", PLY_U8},     {"int16", PLY_I16},    {"uint16", PLY_U16},
    {"int32", PLY_I32},   {"uint32", PLY_U32},   {"float32", PLY_F32},  {"float64", PLY_F64},
};
static const size_t type_size[] = {0, 1, 1, 2, 2, 4, 4, 4, 8};
static const char *const type_label[] = {"none", "char", "uchar", "short", "ushort", "int", "uint", "float", "double"};
static const double type_min[] = {0, -128, 0, -32768, 0, -2147483648.0, 0, -DBL_MAX, -DBL_MAX};
static const double type_max[] = {0, 127, 255, 32767, 65535, 2147483647.0, 4294967295.0, DBL_MAX, DBL_MAX};

static bool type_is_float(ply_type t) { return t == PLY_F32 || t == PLY_F64; }

// What a property feeds in the mesh. The order inside each group matters (x y z, r g b, u v).
typedef enum ply_role {
    ROLE_SKIP,
    ROLE_X, ROLE_Y, ROLE_Z,
    ROLE_NX, ROLE_NY, ROLE_NZ,
    ROLE_R, ROLE_G, ROLE_B,
    ROLE_U, ROLE_V,
    ROLE_REGION,
    ROLE_INDICES,
    ROLE_COUNT
} ply_role;

// Vertex property names; `family` tells synonyms apart (red vs diffuse_red): per group, the first
// family with every member present wins and the others are skipped.
static const struct {
    const char *name;
    ply_role role;
    uint8_t family;
} vertex_names[] = {
    {"x", ROLE_X, 0},          {"y", ROLE_Y, 0},           {"z", ROLE_Z, 0},
    {"nx", ROLE_NX, 0},        {"ny", ROLE_NY, 0},         {"nz", ROLE_NZ, 0},
    {"red", ROLE_R, 0},        {"green", ROLE_G, 0},       {"blue", ROLE_B, 0},
    {"diffuse_red", ROLE_R, 1}, {"diffuse_green", ROLE_G, 1}, {"diffuse_blue", ROLE_B, 1},
    {"s", ROLE_U, 0},          {"t", ROLE_V, 0},
    {"u", ROLE_U, 1},          {"v", ROLE_V, 1},
    {"texture_u", ROLE_U, 2},  {"texture_v", ROLE_V, 2},
    {"region", ROLE_REGION, 0},
};
#define PLY_FAMILIES 3

static const struct {
    ply_role first;
    unsigned n;
    bool required;
    const char *what;
} vertex_groups[] = {
    {ROLE_X, 3, true, "position (x y z)"},
    {ROLE_NX, 3, false, "normal (nx ny nz)"},
    {ROLE_R, 3, false, "colour (red green blue)"},
    {ROLE_U, 2, false, "texture coordinate (s t, u v or texture_u texture_v)"},
    {ROLE_REGION, 1, false, "region"},
};

typedef struct ply_prop {
    const char *name;     // points into ply_reader.text
    ply_type type;        // the scalar type, or the item type of a list
    ply_type count_type;  // PLY_NONE for scalars
    ply_role role;
    uint8_t family;
    uint32_t offset;      // byte offset inside a binary record (elements without lists only)
} ply_prop;

typedef struct ply_element {
    const char *name;
    uint32_t count;
    uint32_t first_prop, prop_count;
    uint32_t line;        // header line, for messages
    bool has_list;
    size_t min_size;      // binary bytes per record: exact without lists, lists counted as empty
} ply_element;

typedef struct ply_reader {
    const char *name;     // path for messages
    const uint8_t *data;
    size_t len, pos;
    uint32_t line;        // 1-based; header lines, then ASCII body lines
    bool in_header;       // messages give the line (header, ASCII) or the byte (binary body)
    bool have_format;
    bool warned_face_extra;
    ply_format format;
    rs_error *err;
    char *text;           // NUL-terminated header copy; names point into it
    ply_element elems[PLY_MAX_ELEMENTS];
    ply_prop props[PLY_MAX_PROPS];
    uint32_t elem_count, prop_count;
    const ply_element *vertex, *face;
    ply_type role_type[ROLE_COUNT];  // type of the vertex property feeding each role
    rs_ply_mesh *mesh;
    size_t tri_cap, tri_max;
    uint32_t fan_first, fan_prev;    // the polygon being fan-triangulated
} ply_reader;

// "<path>: <what> (line N)" in the header and ASCII bodies, "(byte N)" in binary bodies. The parts are
// capped so the location always fits in rs_error.msg; a long path keeps its end (the file name).
__attribute__((format(printf, 3, 4)))
static rs_result fail(ply_reader *r, rs_result code, const char *fmt, ...)
{
    char what[300];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    size_t n = strlen(r->name);
    const char *dots = n > 160 ? "..." : "", *name = n > 160 ? r->name + n - 157 : r->name;
    if (r->in_header || r->format == PLY_ASCII)
        return rs_fail(r->err, code, "%s%s: %s (line %u)", dots, name, what, r->line);
    return rs_fail(r->err, code, "%s%s: %s (byte %zu)", dots, name, what, r->pos);
}

// Notes what was accepted though the format does not allow it (mainstream readers accept it too and the
// meaning is unambiguous), with the line, for the caller to show.
static void warn(ply_reader *r, const char *what)
{
    char *w = r->mesh->warnings;
    size_t n = strlen(w);
    if (n + 4 < sizeof r->mesh->warnings)
        snprintf(w + n, sizeof r->mesh->warnings - n, "%s%s (line %u)", n ? "; " : "", what, r->line);
}

// ---------------------------------------------------------------------------------------------------
// Header

static bool is_blank(int c) { return c == ' ' || c == '\t'; }

// Splits `s` in place at blanks; returns the number of tokens (at most max, the rest stays in the last).
static unsigned split(char *s, char **tok, unsigned max)
{
    unsigned n = 0;
    while (n < max) {
        while (is_blank(*s)) s++;
        if (!*s) break;
        tok[n++] = s;
        while (*s && !is_blank(*s)) s++;
        if (!*s) break;
        *s++ = 0;
    }
    return n;
}

static ply_type parse_type(const char *s)
{
    for (size_t i = 0; i < RS_COUNT_OF(type_names); i++)
        if (strcmp(s, type_names[i].name) == 0) return type_names[i].type;
    return PLY_NONE;
}

static rs_result header_element(ply_reader *r, char **tok, unsigned n)
{
    if (n != 3) return fail(r, RS_ERR_FORMAT, "element line needs a name and a count");
    if (r->elem_count == PLY_MAX_ELEMENTS)
        return fail(r, RS_ERR_LIMIT, "more than %u elements", PLY_MAX_ELEMENTS);
    for (uint32_t i = 0; i < r->elem_count; i++)
        if (strcmp(r->elems[i].name, tok[1]) == 0)
            return fail(r, RS_ERR_FORMAT, "duplicate element '%.64s'", tok[1]);
    uint64_t count = 0;
    for (const char *c = tok[2]; *c; c++) {
        if (*c < '0' || *c > '9')
            return fail(r, RS_ERR_FORMAT, "element %.64s: count '%.32s' is not a number", tok[1], tok[2]);
        count = count * 10 + (uint64_t)(*c - '0');
        if (count > UINT32_MAX)
            return fail(r, RS_ERR_LIMIT, "element %.64s: count %.32s exceeds %u", tok[1], tok[2], UINT32_MAX);
    }
    ply_element *e = &r->elems[r->elem_count++];
    *e = (ply_element){.name = tok[1], .count = (uint32_t)count, .first_prop = r->prop_count, .line = r->line};
    return RS_OK;
}

static rs_result header_property(ply_reader *r, char **tok, unsigned n)
{
    if (r->elem_count == 0) return fail(r, RS_ERR_FORMAT, "property before any element");
    ply_element *e = &r->elems[r->elem_count - 1];
    ply_prop p = {0};
    if (n >= 2 && strcmp(tok[1], "list") == 0) {
        if (n != 5) return fail(r, RS_ERR_FORMAT, "list property needs a count type, an item type and a name");
        p.count_type = parse_type(tok[2]);
        p.type = parse_type(tok[3]);
        p.name = tok[4];
        const char *bad = p.count_type == PLY_NONE ? tok[2] : p.type == PLY_NONE ? tok[3] : NULL;
        if (bad) return fail(r, RS_ERR_FORMAT, "property %.64s: unknown type '%.32s'", p.name, bad);
        if (type_is_float(p.count_type))
            return fail(r, RS_ERR_FORMAT, "property %.64s: list count type must be an integer type", p.name);
    } else {
        if (n != 3) return fail(r, RS_ERR_FORMAT, "property line needs a type and a name");
        p.type = parse_type(tok[1]);
        p.name = tok[2];
        if (p.type == PLY_NONE) return fail(r, RS_ERR_FORMAT, "property %.64s: unknown type '%.32s'", p.name, tok[1]);
    }
    for (uint32_t i = 0; i < e->prop_count; i++)
        if (strcmp(r->props[e->first_prop + i].name, p.name) == 0)
            return fail(r, RS_ERR_FORMAT, "element %.64s: duplicate property '%.64s'", e->name, p.name);
    if (r->prop_count == PLY_MAX_PROPS) return fail(r, RS_ERR_LIMIT, "more than %u properties", PLY_MAX_PROPS);
    r->props[r->prop_count++] = p;
    e->prop_count++;
    return RS_OK;
}

static rs_result header_format(ply_reader *r, char **tok, unsigned n)
{
    if (r->have_format) return fail(r, RS_ERR_FORMAT, "second format line");
    if (n != 3) return fail(r, RS_ERR_FORMAT, "format line needs a format and a version");
    if (strcmp(tok[1], "ascii") == 0) r->format = PLY_ASCII;
    else if (strcmp(tok[1], "binary_little_endian") == 0) r->format = PLY_LE;
    else if (strcmp(tok[1], "binary_big_endian") == 0) r->format = PLY_BE;
    else return fail(r, RS_ERR_FORMAT, "unknown format '%.40s'", tok[1]);
    if (strcmp(tok[2], "1.0") != 0) return fail(r, RS_ERR_FORMAT, "unsupported PLY version '%.20s'", tok[2]);
    r->have_format = true;
    return RS_OK;
}

// "comment" lines are kept, joined by '\n'; "comment TextureFile NAME" also names the texture.
static rs_result header_comment(ply_reader *r, char *text, size_t *comments_len)
{
    rs_ply_mesh *m = r->mesh;
    while (is_blank(*text)) text++;
    size_t n = strlen(text);
    if (*comments_len) m->comments[(*comments_len)++] = '\n';
    memcpy(m->comments + *comments_len, text, n + 1);
    *comments_len += n;
    if (!m->texture_file && strncmp(text, "TextureFile", 11) == 0 && is_blank(text[11])) {
        const char *name = text + 12;
        while (is_blank(*name)) name++;
        if (*name) {
            m->texture_file = strdup(name);
            if (!m->texture_file) return fail(r, RS_ERR_NOMEM, "out of memory");
        }
    }
    return RS_OK;
}

static rs_result header_line(ply_reader *r, char *s, size_t *comments_len, bool *ended)
{
    while (is_blank(*s)) s++;
    if (r->line == 1) {
        if (strcmp(s, "ply") != 0) return fail(r, RS_ERR_FORMAT, "not a PLY file (first line is not 'ply')");
        return RS_OK;
    }
    if (strncmp(s, "comment", 7) == 0 && (!s[7] || is_blank(s[7])))
        return header_comment(r, s + 7, comments_len);
    char whole[PLY_MAX_LINE + 1];  // split() cuts s into tokens; free text before the elements keeps it whole
    snprintf(whole, sizeof whole, "%s", s);
    char *tok[6];
    unsigned n = split(s, tok, RS_COUNT_OF(tok));
    if (n == 0) return RS_OK;  // blank line: tolerated
    if (strcmp(tok[0], "obj_info") == 0) return RS_OK;
    if (strcmp(tok[0], "format") == 0) return header_format(r, tok, n);
    if (strcmp(tok[0], "element") == 0) return header_element(r, tok, n);
    if (strcmp(tok[0], "property") == 0) return header_property(r, tok, n);
    if (strcmp(tok[0], "end_header") == 0) {
        if (n != 1) return fail(r, RS_ERR_FORMAT, "text after end_header");
        *ended = true;
        return RS_OK;
    }
    // Some writers (Blender 2.47: "Created by Blender ...") put free text before the elements without
    // "comment": kept as a comment. After the first element an unknown keyword is an error (a typo there
    // would silently drop a property).
    if (r->elem_count == 0) {
        warn(r, "header text without 'comment' taken as a comment");
        return header_comment(r, whole, comments_len);
    }
    return fail(r, RS_ERR_FORMAT, "unknown header keyword '%.40s'", tok[0]);
}

// Reads the header lines into r->elems/r->props and the comments into the mesh; leaves r->pos at
// the first body byte.
static rs_result read_header_lines(ply_reader *r)
{
    size_t limit = RS_MIN(r->len, (size_t)PLY_MAX_HEADER);
    r->text = malloc(limit + 1);
    r->mesh->comments = malloc(limit + 1);
    if (!r->text || !r->mesh->comments) return fail(r, RS_ERR_NOMEM, "out of memory for the header");
    memcpy(r->text, r->data, limit);
    r->text[limit] = 0;
    r->mesh->comments[0] = 0;
    size_t comments_len = 0;
    bool ended = false;
    r->pos = 0;
    // A UTF-8 byte-order mark before "ply" (Windows editors write one) carries no meaning: skip it.
    if (limit >= 3 && memcmp(r->data, "\xef\xbb\xbf", 3) == 0) {
        r->pos = 3;
        r->line = 1;
        warn(r, "UTF-8 byte-order mark before 'ply' skipped");
        r->line = 0;
    }
    while (!ended) {
        r->line++;
        if (r->pos >= limit) {
            if (r->len == 0) return fail(r, RS_ERR_FORMAT, "not a PLY file (empty)");
            if (r->len > limit) return fail(r, RS_ERR_LIMIT, "header longer than %u bytes", PLY_MAX_HEADER);
            return fail(r, RS_ERR_FORMAT, "missing end_header");
        }
        const uint8_t *nl = memchr(r->data + r->pos, '\n', limit - r->pos);
        size_t end = nl ? (size_t)(nl - r->data) : limit;
        if (!nl && r->len > limit) return fail(r, RS_ERR_LIMIT, "header longer than %u bytes", PLY_MAX_HEADER);
        if (end - r->pos > PLY_MAX_LINE)
            return fail(r, RS_ERR_LIMIT, "header line longer than %u bytes", PLY_MAX_LINE);
        char *s = r->text + r->pos;
        size_t n = end - r->pos;
        // Trailing blanks and the '\r' of CRLF files go; any other control byte (a NUL included) is an
        // error, which also keeps every later message one printable line.
        while (n > 0 && (is_blank(s[n - 1]) || s[n - 1] == '\r')) n--;
        s[n] = 0;
        for (size_t i = 0; i < n; i++) {
            unsigned char c = (unsigned char)s[i];
            if ((c < 0x20 && c != '\t') || c == 0x7f)
                return fail(r, RS_ERR_FORMAT, "control byte 0x%02x in the header", c);
        }
        r->pos = nl ? end + 1 : end;
        rs_result res = header_line(r, s, &comments_len, &ended);
        if (res != RS_OK) return res;
    }
    if (!r->have_format) return fail(r, RS_ERR_FORMAT, "no format line before end_header");
    return RS_OK;
}

static rs_result resolve_vertex(ply_reader *r, ply_element *e)
{
    ply_prop *props = &r->props[e->first_prop];
    uint8_t mask[ROLE_COUNT][PLY_FAMILIES] = {{0}};  // indexed by the group's first role
    for (uint32_t k = 0; k < e->prop_count; k++) {
        ply_prop *p = &props[k];
        for (size_t i = 0; i < RS_COUNT_OF(vertex_names); i++) {
            if (strcmp(p->name, vertex_names[i].name) != 0) continue;
            if (p->count_type != PLY_NONE)
                return fail(r, RS_ERR_FORMAT, "vertex property %s must not be a list", p->name);
            if (vertex_names[i].role == ROLE_REGION && type_is_float(p->type))
                return fail(r, RS_ERR_FORMAT, "vertex property region must have an integer type, not %s",
                            type_label[p->type]);
            p->role = vertex_names[i].role;
            p->family = vertex_names[i].family;
        }
    }
    uint8_t chosen[ROLE_COUNT] = {0};
    for (size_t g = 0; g < RS_COUNT_OF(vertex_groups); g++) {
        ply_role first = vertex_groups[g].first;
        unsigned full = (1u << vertex_groups[g].n) - 1;
        for (uint32_t k = 0; k < e->prop_count; k++) {
            const ply_prop *p = &props[k];
            if (p->role >= first && p->role < first + vertex_groups[g].n)
                mask[first][p->family] |= (uint8_t)(1u << (p->role - first));
        }
        chosen[first] = PLY_FAMILIES;
        bool partial = false;
        for (unsigned f = 0; f < PLY_FAMILIES; f++) {
            if (mask[first][f] == full && chosen[first] == PLY_FAMILIES) chosen[first] = (uint8_t)f;
            if (mask[first][f] && mask[first][f] != full) partial = true;
        }
        if (chosen[first] == PLY_FAMILIES && (partial || vertex_groups[g].required))
            return fail(r, RS_ERR_FORMAT, "element vertex: incomplete %s", vertex_groups[g].what);
    }
    // Roles of the losing synonyms are dropped; the winners remember their types for conversion.
    for (uint32_t k = 0; k < e->prop_count; k++) {
        ply_prop *p = &props[k];
        if (p->role == ROLE_SKIP) continue;
        ply_role first = ROLE_SKIP;
        for (size_t g = 0; g < RS_COUNT_OF(vertex_groups); g++)
            if (p->role >= vertex_groups[g].first && p->role < vertex_groups[g].first + vertex_groups[g].n)
                first = vertex_groups[g].first;
        if (chosen[first] != p->family) p->role = ROLE_SKIP;
        else r->role_type[p->role] = p->type;
    }
    return RS_OK;
}

static rs_result resolve_face(ply_reader *r, ply_element *e)
{
    for (uint32_t k = 0; k < e->prop_count; k++) {
        ply_prop *p = &r->props[e->first_prop + k];
        if (strcmp(p->name, "vertex_indices") != 0 && strcmp(p->name, "vertex_index") != 0) continue;
        if (p->count_type == PLY_NONE) return fail(r, RS_ERR_FORMAT, "face property %s must be a list", p->name);
        if (type_is_float(p->type))
            return fail(r, RS_ERR_FORMAT, "face property %s: index type must be an integer type, not %s", p->name,
                        type_label[p->type]);
        p->role = ROLE_INDICES;
        return RS_OK;
    }
    return fail(r, RS_ERR_FORMAT, "element face has no vertex_indices list");
}

static rs_result read_header(ply_reader *r)
{
    r->in_header = true;
    rs_result res = read_header_lines(r);
    if (res != RS_OK) return res;
    uint32_t end_line = r->line;
    for (uint32_t i = 0; i < r->elem_count; i++) {
        ply_element *e = &r->elems[i];
        r->line = e->line;
        if (strcmp(e->name, "vertex") == 0) {
            if ((res = resolve_vertex(r, e)) != RS_OK) return res;
            r->vertex = e;
        } else if (strcmp(e->name, "face") == 0) {
            if ((res = resolve_face(r, e)) != RS_OK) return res;
            r->face = e;
        } else if (strcmp(e->name, "tristrips") == 0 && e->count > 0) {
            // Read without them, a strip-only mesh (Cyberware's Igea) would silently become a point cloud.
            return fail(r, RS_ERR_FORMAT, "element tristrips: triangle strips are not read; convert them to a face list "
                                          "first (e.g. MeshLab: File > Export Mesh As... PLY)");
        }
        for (uint32_t k = 0; k < e->prop_count; k++) {
            ply_prop *p = &r->props[e->first_prop + k];
            p->offset = (uint32_t)e->min_size;
            e->min_size += type_size[p->count_type != PLY_NONE ? p->count_type : p->type];
            e->has_list |= p->count_type != PLY_NONE;
        }
    }
    if (!r->vertex) return fail(r, RS_ERR_FORMAT, "no vertex element");
    r->line = end_line;
    r->in_header = false;
    return RS_OK;
}

// ---------------------------------------------------------------------------------------------------
// Values shared by both encodings

static float to_float(double v) { return (float)RS_CLAMP(v, -FLT_MAX, FLT_MAX); }

// uchar as is; other integers clamped to 0..255; floats are 0..1, clamped, scaled and rounded.
static uint8_t to_byte(double v, ply_type t)
{
    if (type_is_float(t)) {
        if (!(v > 0)) return 0;  // NaN too
        return v >= 1 ? 255 : (uint8_t)(v * 255.0 + 0.5);
    }
    return (uint8_t)RS_CLAMP(v, 0.0, 255.0);
}

static rs_result commit_vertex(ply_reader *r, uint32_t i, const double *v)
{
    rs_ply_mesh *m = r->mesh;
    for (int k = 0; k < 3; k++) {
        double c = v[ROLE_X + k];
        // Out-of-range doubles would become infinities in float: refused like NaN and inf.
        if (!(fabs(c) <= FLT_MAX))
            return fail(r, RS_ERR_FORMAT, "vertex %u: position %c is %s", i, "xyz"[k],
                        isnan(c) ? "NaN" : "infinite or beyond float range");
        m->pos[i][k] = (float)c;
    }
    if (m->normal)
        // A normal that is not a finite float (NaN, inf, 1e300) becomes NaN: the converter then sees it as
        // unusable and re-estimates it, instead of trusting a clamped (-FLT_MAX, ...) direction.
        for (int k = 0; k < 3; k++) m->normal[i][k] = fabs(v[ROLE_NX + k]) <= FLT_MAX ? (float)v[ROLE_NX + k] : NAN;
    if (m->rgb)
        for (int k = 0; k < 3; k++) m->rgb[i][k] = to_byte(v[ROLE_R + k], r->role_type[ROLE_R + k]);
    if (m->uv)
        for (int k = 0; k < 2; k++) m->uv[i][k] = to_float(v[ROLE_U + k]);
    if (m->region) {
        double g = v[ROLE_REGION];
        if (g < 0 || g > 255) return fail(r, RS_ERR_FORMAT, "vertex %u: region %.0f is outside 0..255", i, g);
        m->region[i] = (uint8_t)g;
    }
    return RS_OK;
}

static rs_result push_tri(ply_reader *r, uint32_t a, uint32_t b, uint32_t c)
{
    rs_ply_mesh *m = r->mesh;
    if (m->tri_count == r->tri_cap) {
        // Doubling, but never past what the remaining bytes can describe (tri_max).
        size_t cap = RS_MIN(RS_MAX(r->tri_cap * 2, (size_t)64), r->tri_max);
        size_t bytes;
        if (cap <= r->tri_cap || !rs_size_mul(cap, sizeof *m->tri, &bytes))
            return fail(r, RS_ERR_LIMIT, "more than %zu triangles", r->tri_max);
        void *grown = realloc(m->tri, bytes);
        if (!grown) return fail(r, RS_ERR_NOMEM, "out of memory for %zu triangles", cap);
        m->tri = grown;
        r->tri_cap = cap;
    }
    m->tri[m->tri_count][0] = a;
    m->tri[m->tri_count][1] = b;
    m->tri[m->tri_count][2] = c;
    m->tri_count++;
    return RS_OK;
}

// Item k of face `face`'s index list: validated, then fanned as (v0, v[k-1], v[k]).
static rs_result polygon_index(ply_reader *r, uint32_t face, size_t k, double idx)
{
    if (!(idx >= 0 && idx < (double)r->vertex->count))
        return fail(r, RS_ERR_FORMAT, "face %u: vertex index %.0f out of range (%u vertices)", face, idx,
                    r->vertex->count);
    uint32_t i = (uint32_t)idx;
    rs_result res = RS_OK;
    if (k == 0) r->fan_first = i;
    else if (k >= 2) res = push_tri(r, r->fan_first, r->fan_prev, i);
    r->fan_prev = i;
    return res;
}

// ---------------------------------------------------------------------------------------------------
// Binary body

// Assembles n bytes in file order; compilers turn this into one load (plus a byte swap).
static inline uint64_t load_bits(const uint8_t *p, unsigned n, bool big)
{
    uint64_t u = 0;
    if (big)
        for (unsigned i = 0; i < n; i++) u = u << 8 | p[i];
    else
        for (unsigned i = 0; i < n; i++) u |= (uint64_t)p[i] << (8 * i);
    return u;
}

static inline double read_num(const uint8_t *p, ply_type t, bool big)
{
    switch (t) {
    case PLY_I8: return (double)p[0] - (p[0] & 0x80 ? 256.0 : 0.0);
    case PLY_U8: return p[0];
    case PLY_I16: {
        uint64_t u = load_bits(p, 2, big);
        return (double)u - (u & 0x8000u ? 65536.0 : 0.0);
    }
    case PLY_U16: return (double)load_bits(p, 2, big);
    case PLY_I32: {
        uint64_t u = load_bits(p, 4, big);
        return (double)u - (u & 0x80000000u ? 4294967296.0 : 0.0);
    }
    case PLY_U32: return (double)load_bits(p, 4, big);
    case PLY_F32: {
        uint32_t u = (uint32_t)load_bits(p, 4, big);
        float f;
        memcpy(&f, &u, sizeof f);
        return f;
    }
    case PLY_F64: {
        uint64_t u = load_bits(p, 8, big);
        double d;
        memcpy(&d, &u, sizeof d);
        return d;
    }
    case PLY_NONE: break;
    }
    return 0;
}

static rs_result element_too_big(ply_reader *r, const ply_element *e, size_t min_size, size_t left)
{
    return fail(r, RS_ERR_FORMAT, "element %.64s: %u records of at least %zu bytes do not fit in the %zu bytes left",
                e->name, e->count, min_size, left);
}

// Fast path: every record has the same size, so the whole element is bounds-checked once.
static rs_result read_binary_fixed(ply_reader *r, const ply_element *e)
{
    size_t total, left = r->len - r->pos;
    if (!rs_size_mul(e->count, e->min_size, &total) || total > left) return element_too_big(r, e, e->min_size, left);
    if (e == r->vertex) {
        const ply_prop *used[ROLE_COUNT];
        unsigned nused = 0;
        for (uint32_t k = 0; k < e->prop_count; k++)
            if (r->props[e->first_prop + k].role != ROLE_SKIP) used[nused++] = &r->props[e->first_prop + k];
        bool big = r->format == PLY_BE;
        double v[ROLE_COUNT] = {0};
        size_t start = r->pos;
        for (uint32_t i = 0; i < e->count; i++) {
            const uint8_t *rec = r->data + start + (size_t)i * e->min_size;
            for (unsigned k = 0; k < nused; k++) v[used[k]->role] = read_num(rec + used[k]->offset, used[k]->type, big);
            r->pos = (size_t)(rec - r->data);
            rs_result res = commit_vertex(r, i, v);
            if (res != RS_OK) return res;
        }
        r->pos = start;
    }
    r->pos += total;
    return RS_OK;
}

static rs_result truncated(ply_reader *r, const ply_element *e, uint32_t rec, const ply_prop *p)
{
    return fail(r, RS_ERR_FORMAT, "%.64s %u: data ends inside property %.64s", e->name, rec, p->name);
}

// General path: records with lists, read property by property with a bounds check before each read.
static rs_result read_binary_record(ply_reader *r, const ply_element *e, uint32_t rec, double *v)
{
    bool big = r->format == PLY_BE;
    for (uint32_t k = 0; k < e->prop_count; k++) {
        const ply_prop *p = &r->props[e->first_prop + k];
        if (p->count_type == PLY_NONE) {
            size_t size = type_size[p->type];
            if (r->len - r->pos < size) return truncated(r, e, rec, p);
            if (p->role != ROLE_SKIP) v[p->role] = read_num(r->data + r->pos, p->type, big);
            r->pos += size;
            continue;
        }
        size_t csize = type_size[p->count_type], isize = type_size[p->type];
        if (r->len - r->pos < csize) return truncated(r, e, rec, p);
        double n = read_num(r->data + r->pos, p->count_type, big);
        if (n < 0) return fail(r, RS_ERR_FORMAT, "%.64s %u: property %.64s: negative list count %.0f", e->name, rec, p->name, n);
        size_t left = r->len - r->pos - csize;
        if (n > (double)(left / isize))
            return fail(r, RS_ERR_FORMAT, "%.64s %u: property %.64s: list of %.0f items does not fit in the %zu bytes left",
                        e->name, rec, p->name, n, left);
        r->pos += csize;
        size_t count = (size_t)n;
        if (p->role != ROLE_INDICES) {
            r->pos += count * isize;
            continue;
        }
        for (size_t i = 0; i < count; i++) {
            rs_result res = polygon_index(r, rec, i, read_num(r->data + r->pos, p->type, big));
            if (res != RS_OK) return res;
            r->pos += isize;
        }
    }
    return RS_OK;
}

// ---------------------------------------------------------------------------------------------------
// ASCII body: one record per line, blank lines skipped

static bool is_space(int c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

// Moves to the first byte of the next non-blank line; false at the end of the data.
static bool ascii_next_line(ply_reader *r)
{
    while (r->pos < r->len) {
        uint8_t c = r->data[r->pos];
        if (c == '\n') r->line++;
        else if (!is_space(c)) return true;
        r->pos++;
    }
    return false;
}

// Keeps printable ASCII of a bad token for the message.
static void printable(char *dst, size_t cap, const uint8_t *src, size_t n)
{
    size_t k = 0;
    for (; k < n && k + 1 < cap; k++) dst[k] = src[k] >= 0x20 && src[k] < 0x7f ? (char)src[k] : '?';
    dst[k] = 0;
}

static rs_result ascii_number(ply_reader *r, const ply_element *e, uint32_t rec, const ply_prop *p, ply_type t,
                              double *out)
{
    while (r->pos < r->len && is_space(r->data[r->pos])) r->pos++;
    if (r->pos == r->len || r->data[r->pos] == '\n')
        return fail(r, RS_ERR_FORMAT, "%.64s %u: too few values, property %.64s is missing", e->name, rec, p->name);
    size_t start = r->pos;
    while (r->pos < r->len && r->data[r->pos] != '\n' && !is_space(r->data[r->pos])) r->pos++;
    size_t n = r->pos - start;
    char buf[PLY_MAX_TOKEN + 1];
    if (n > PLY_MAX_TOKEN)
        return fail(r, RS_ERR_FORMAT, "%.64s %u: property %.64s: value longer than %u characters", e->name, rec, p->name,
                    PLY_MAX_TOKEN);
    memcpy(buf, r->data + start, n);
    buf[n] = 0;
    char *end;
    errno = 0;
    double v;
    if (type_is_float(t)) {
        v = strtod(buf, &end);
    } else {
        long long i = strtoll(buf, &end, 10);
        v = (double)i;
        if (end == buf + n && (errno == ERANGE || v < type_min[t] || v > type_max[t]))
            return fail(r, RS_ERR_FORMAT, "%.64s %u: property %.64s: %s is out of range for %s", e->name, rec, p->name, buf,
                        type_label[t]);
    }
    if (end != buf + n) {
        char shown[33];
        printable(shown, sizeof shown, r->data + start, n);
        return fail(r, RS_ERR_FORMAT, "%.64s %u: property %.64s: '%s' is not %s", e->name, rec, p->name, shown,
                    type_is_float(t) ? "a number" : "an integer");
    }
    *out = v;
    return RS_OK;
}

static rs_result read_ascii_record(ply_reader *r, const ply_element *e, uint32_t rec, double *v)
{
    if (!ascii_next_line(r))
        return fail(r, RS_ERR_FORMAT, "%.64s %u: data ends before this record (%u declared)", e->name, rec, e->count);
    rs_result res;
    for (uint32_t k = 0; k < e->prop_count; k++) {
        const ply_prop *p = &r->props[e->first_prop + k];
        double x;
        if (p->count_type == PLY_NONE) {
            if ((res = ascii_number(r, e, rec, p, p->type, &x)) != RS_OK) return res;
            if (p->role != ROLE_SKIP) v[p->role] = x;
            continue;
        }
        double n;
        if ((res = ascii_number(r, e, rec, p, p->count_type, &n)) != RS_OK) return res;
        // Each item takes at least two bytes ("1 "), but the last may end the file.
        if (n < 0 || n > (double)((r->len - r->pos) / 2 + 1))
            return fail(r, RS_ERR_FORMAT, "%.64s %u: property %.64s: list count %.0f is negative or exceeds the data left",
                        e->name, rec, p->name, n);
        for (size_t i = 0; i < (size_t)n; i++) {
            if ((res = ascii_number(r, e, rec, p, p->type, &x)) != RS_OK) return res;
            if (p->role == ROLE_INDICES && (res = polygon_index(r, rec, i, x)) != RS_OK) return res;
        }
    }
    while (r->pos < r->len && is_space(r->data[r->pos])) r->pos++;
    if (r->pos < r->len && r->data[r->pos] != '\n') {
        // Faces with undeclared trailing values (trimesh's and some exporters' per-face extras): the
        // declared list is complete, so the rest of the line is skipped. Vertices stay strict.
        if (e != r->face) return fail(r, RS_ERR_FORMAT, "%.64s %u: more values than the header declares", e->name, rec);
        if (!r->warned_face_extra) warn(r, "faces carry values the header does not declare: ignored");
        r->warned_face_extra = true;
        while (r->pos < r->len && r->data[r->pos] != '\n') r->pos++;
    }
    return RS_OK;
}

// ---------------------------------------------------------------------------------------------------
// Body

// Checks the element's count against the bytes left (so allocations below stay bounded by the file
// size) and prepares the mesh arrays it fills.
static rs_result begin_element(ply_reader *r, const ply_element *e)
{
    size_t left = r->len - r->pos, need;
    // ASCII: each value takes at least two bytes ("1 "), except the very last one.
    size_t min_size = r->format == PLY_ASCII ? 2 * (size_t)e->prop_count : e->min_size;
    if (!rs_size_mul(e->count, min_size, &need) || (need > left + (r->format == PLY_ASCII && need > 0)))
        return element_too_big(r, e, min_size, left);
    rs_ply_mesh *m = r->mesh;
    if (e == r->vertex) {
        size_t n = e->count;
        m->vertex_count = e->count;
        m->pos = rs_alloc_array(n, sizeof *m->pos);
        bool fail_alloc = !m->pos;
        if (r->role_type[ROLE_NX]) fail_alloc |= !(m->normal = rs_alloc_array(n, sizeof *m->normal));
        if (r->role_type[ROLE_R]) fail_alloc |= !(m->rgb = rs_alloc_array(n, sizeof *m->rgb));
        if (r->role_type[ROLE_U]) fail_alloc |= !(m->uv = rs_alloc_array(n, sizeof *m->uv));
        if (r->role_type[ROLE_REGION]) fail_alloc |= !(m->region = rs_alloc_array(n, sizeof *m->region));
        if (fail_alloc) return fail(r, RS_ERR_NOMEM, "out of memory for %u vertices", e->count);
    } else if (e == r->face) {
        // A triangle needs one more index than the previous one of its polygon, so the bytes left
        // bound the number of triangles; the first allocation assumes all faces are triangles.
        const ply_prop *idx = NULL;
        for (uint32_t k = 0; k < e->prop_count; k++)
            if (r->props[e->first_prop + k].role == ROLE_INDICES) idx = &r->props[e->first_prop + k];
        size_t isize = r->format == PLY_ASCII ? 2 : type_size[idx->type];
        size_t tri_size = r->format == PLY_ASCII ? 8 : type_size[idx->count_type] + 3 * isize;
        r->tri_max = RS_MIN(left / isize + 1, (size_t)UINT32_MAX);
        r->tri_cap = RS_MIN((size_t)e->count, left / tri_size);
        if (r->tri_cap && !(m->tri = rs_alloc_array(r->tri_cap, sizeof *m->tri)))
            return fail(r, RS_ERR_NOMEM, "out of memory for %zu triangles", r->tri_cap);
    }
    return RS_OK;
}

static rs_result read_body(ply_reader *r)
{
    if (r->format == PLY_ASCII) r->line++;  // the body starts on the line after end_header
    for (uint32_t i = 0; i < r->elem_count; i++) {
        const ply_element *e = &r->elems[i];
        rs_result res = begin_element(r, e);
        if (res != RS_OK) return res;
        if (e->prop_count == 0) continue;
        if (r->format != PLY_ASCII && !e->has_list) {
            if ((res = read_binary_fixed(r, e)) != RS_OK) return res;
            continue;
        }
        double v[ROLE_COUNT] = {0};
        for (uint32_t rec = 0; rec < e->count; rec++) {
            size_t start = r->pos;
            res = r->format == PLY_ASCII ? read_ascii_record(r, e, rec, v) : read_binary_record(r, e, rec, v);
            if (res != RS_OK) return res;
            if (e == r->vertex) {
                size_t end = r->pos;
                r->pos = r->format == PLY_ASCII ? end : start;
                if ((res = commit_vertex(r, rec, v)) != RS_OK) return res;
                r->pos = end;
            }
        }
    }
    // Trailing bytes after the last element are ignored, as other readers do.
    return RS_OK;
}

static rs_result load_named(const char *name, const void *data, size_t len, rs_ply_mesh **out, rs_error *err)
{
    assert((data || len == 0) && out);
    ply_reader *r = calloc(1, sizeof *r);
    rs_ply_mesh *m = calloc(1, sizeof *m);
    if (!r || !m) {
        free(r);
        free(m);
        return rs_fail(err, RS_ERR_NOMEM, "%s: out of memory", name);
    }
    *r = (ply_reader){.name = name, .data = data, .len = len, .err = err, .mesh = m};
    rs_result res = read_header(r);
    if (res == RS_OK) res = read_body(r);
    free(r->text);
    free(r);
    if (res != RS_OK) {
        rs_ply_destroy(m);
        return res;
    }
    if (m->tri_count == 0) {
        free(m->tri);
        m->tri = NULL;
    } else {
        void *fit = realloc(m->tri, (size_t)m->tri_count * sizeof *m->tri);
        if (fit) m->tri = fit;
    }
    *out = m;
    return RS_OK;
}

rs_result rs_ply_load_memory(const void *data, size_t len, rs_ply_mesh **out, rs_error *err)
{
    return load_named("<memory>", data, len, out, err);
}

rs_result rs_ply_load(const char *path, rs_ply_mesh **out, rs_error *err)
{
    void *data = NULL;
    size_t len = 0;
    rs_result res = rs_file_read_all(path, RS_PLY_MAX_FILE, &data, &len, err);
    if (res != RS_OK) return res;
    res = load_named(path, data, len, out, err);
    free(data);
    return res;
}

void rs_ply_destroy(rs_ply_mesh *m)
{
    if (!m) return;
    free(m->pos);
    free(m->normal);
    free(m->rgb);
    free(m->uv);
    free(m->region);
    free(m->tri);
    free(m->tri_page);
    free(m->comments);
    free(m->texture_file);
    free(m);
}
