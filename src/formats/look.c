// look.c — look files (docs/makeup.md): the layer's applied stamps in model space, as text.
//
//   rouge-look 1
//   face height=1.23
//   cosmetic 0 lipstick_satin
//   cosmetic 1 custom name=mine kind=custom rgb=200,80,120 weight=0.6 ...
//   stroke
//   p X Y Z VX VY VZ RADIUS AMOUNT COSMETIC [mask]  paint stamp (mask: kept to the cosmetic's region)
//   e X Y Z VX VY VZ RADIUS AMOUNT              eraser stamp
//   end
//
// Floats are written with 9 significant digits, which round-trip a float exactly, so a look saved and
// loaded on the same cloud replays to byte-identical records.
#define _POSIX_C_SOURCE 200809L  // strtok_r
#include "formats/look.h"
#include "formats/textfile.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void rs_look_destroy(rs_look *look)
{
    if (!look) return;
    free(look->cosmetics);
    free(look->stamps);
    free(look);
}

// --- parsing -------------------------------------------------------------------------------------

typedef struct parser {
    rs_look *look;
    uint32_t line, stamp_cap, cosmetic_cap;
    bool in_stroke, stroke_empty, have_face;
    rs_error *err;
} parser;

static rs_result perr(parser *p, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static rs_result perr(parser *p, const char *fmt, ...)
{
    char msg[400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return rs_fail(p->err, RS_ERR_FORMAT, "line %u: %s", p->line, msg);
}

static rs_result parse_stamp(parser *p, bool eraser, char **save)
{
    rs_look *lk = p->look;
    if (!p->in_stroke) return perr(p, "stamp outside a stroke (missing 'stroke')");
    if (lk->stamp_count >= RS_LOOK_MAX_STAMPS) return perr(p, "more than %u stamps", RS_LOOK_MAX_STAMPS);
    static const char *const names[] = {"x", "y", "z", "view x", "view y", "view z", "radius", "amount"};
    float v[8];
    for (int k = 0; k < 8; k++) {
        char *tok = strtok_r(NULL, " \t", save);
        if (!tok) return perr(p, "stamp: missing %s", names[k]);
        if (!rs_parse_float(tok, &v[k]) || fabsf(v[k]) > RS_LOOK_MAX_COORD)
            return perr(p, "stamp: %s: '%.64s' is not a finite number within %g", names[k], tok, RS_LOOK_MAX_COORD);
    }
    if (!(v[6] > 0.0f)) return perr(p, "stamp: radius: %g, must be > 0", v[6]);
    if (v[7] < 0.0f || v[7] > 1.0f) return perr(p, "stamp: amount: %g not in [0, 1]", v[7]);
    uint32_t cos = 0;
    bool masked = false;
    if (!eraser) {
        char *tok = strtok_r(NULL, " \t", save);
        if (!tok) return perr(p, "stamp: missing cosmetic index");
        if (!rs_text_parse_uint(tok, UINT16_MAX, &cos) || cos >= lk->cosmetic_count)
            return perr(p, "stamp: cosmetic: '%.32s' is not a defined cosmetic index (0..%d)", tok,
                        (int)lk->cosmetic_count - 1);
        char *flag = strtok_r(NULL, " \t", save);
        if (flag && strcmp(flag, "mask") != 0)
            return perr(p, "stamp: unexpected text '%.32s' after the cosmetic index (only 'mask' may follow)", flag);
        masked = flag != NULL;
    }
    if (strtok_r(NULL, " \t", save)) return perr(p, "stamp: unexpected text after the last field");
    if (!rs_array_grow((void **)&lk->stamps, &p->stamp_cap, lk->stamp_count + 1, sizeof *lk->stamps))
        return rs_fail(p->err, RS_ERR_NOMEM, "line %u: out of memory", p->line);
    lk->stamps[lk->stamp_count++] = (rs_makeup_applied){{v[0], v[1], v[2]}, {v[3], v[4], v[5]}, v[6], v[7],
                                                        (uint16_t)cos, eraser, p->stroke_empty, masked};
    p->stroke_empty = false;
    return RS_OK;
}

static rs_result parse_line(parser *p, char *line)
{
    rs_look *lk = p->look;
    char *save = NULL;
    char *kw = strtok_r(line, " \t", &save);
    if (strcmp(kw, "p") == 0 || strcmp(kw, "e") == 0) return parse_stamp(p, kw[0] == 'e', &save);
    if (strcmp(kw, "end") == 0) {
        if (!p->in_stroke) return perr(p, "'end' without 'stroke'");
        if (p->stroke_empty) return perr(p, "stroke has no stamps");
        if (strtok_r(NULL, " \t", &save)) return perr(p, "end: unexpected text");
        p->in_stroke = false;
        return RS_OK;
    }
    if (p->in_stroke) return perr(p, "'%.32s' inside a stroke (missing 'end')", kw);
    if (strcmp(kw, "stroke") == 0) {
        if (!p->have_face) return perr(p, "stroke before the 'face' line");
        if (strtok_r(NULL, " \t", &save)) return perr(p, "stroke: unexpected text");
        p->in_stroke = p->stroke_empty = true;
        return RS_OK;
    }
    if (strcmp(kw, "face") == 0) {
        if (p->have_face) return perr(p, "face: given twice");
        char *tok = strtok_r(NULL, " \t", &save);
        if (!tok || strncmp(tok, "height=", 7) != 0 || !rs_parse_float(tok + 7, &lk->face_height) ||
            !(lk->face_height > 0.0f) || lk->face_height > RS_LOOK_MAX_COORD)
            return perr(p, "face: expected height=H with H > 0");
        if (strtok_r(NULL, " \t", &save)) return perr(p, "face: unexpected text");
        p->have_face = true;
        return RS_OK;
    }
    if (strcmp(kw, "cosmetic") == 0) {
        char *tok = strtok_r(NULL, " \t", &save);
        uint32_t idx;
        if (!tok || !rs_text_parse_uint(tok, RS_LOOK_MAX_COSMETICS, &idx) || idx != lk->cosmetic_count)
            return perr(p, "cosmetic: index must be %u (cosmetics are numbered in order)", lk->cosmetic_count);
        if (idx >= RS_LOOK_MAX_COSMETICS) return perr(p, "cosmetic: more than %d", RS_LOOK_MAX_COSMETICS);
        char *rest = strtok_r(NULL, "", &save);
        if (!rest) return perr(p, "cosmetic %u: missing definition", idx);
        if (!rs_array_grow((void **)&lk->cosmetics, &p->cosmetic_cap, lk->cosmetic_count + 1, sizeof *lk->cosmetics))
            return rs_fail(p->err, RS_ERR_NOMEM, "line %u: out of memory", p->line);
        rs_error inner = {0};
        if (rs_cosmetic_parse(rest, &lk->cosmetics[idx], &inner) != RS_OK) return perr(p, "%s", inner.msg);
        lk->cosmetic_count++;
        return RS_OK;
    }
    return perr(p, "unknown keyword '%.32s'", kw);
}

rs_result rs_look_parse(const void *data, size_t len, rs_look **out, rs_error *err)
{
    if (len > RS_LOOK_MAX_BYTES)
        return rs_fail(err, RS_ERR_LIMIT, "look: %zu bytes, more than %u", len, RS_LOOK_MAX_BYTES);
    rs_look *lk = calloc(1, sizeof *lk);
    if (!lk) return rs_fail(err, RS_ERR_NOMEM, "look: out of memory");
    parser p = {.look = lk, .err = err};
    rs_text_reader t = {.data = data, .len = len};
    bool header = false;
    rs_result r = RS_OK;
    char buf[RS_LOOK_MAX_LINE + 1], *line;
    while (r == RS_OK && rs_text_next_line(&t, buf, sizeof buf, &line, &r, err)) {
        p.line = t.line;
        if (!header) {
            r = rs_text_check_header(line, "rouge-look", RS_LOOK_VERSION, "look file", t.line, err);
            header = true;
            continue;
        }
        r = parse_line(&p, line);
    }
    if (r == RS_OK && !header) r = rs_fail(err, RS_ERR_FORMAT, "look: empty file (no 'rouge-look' line)");
    if (r == RS_OK && !p.have_face) r = rs_fail(err, RS_ERR_FORMAT, "look: missing the 'face' line");
    if (r == RS_OK && p.in_stroke) r = rs_fail(err, RS_ERR_FORMAT, "line %u: file ends inside a stroke", p.line);
    if (r == RS_OK) {
        double cover = 0;
        for (uint32_t i = 0; i < lk->stamp_count; i++) {
            double q = lk->stamps[i].radius / lk->face_height;
            cover += q * q;
        }
        if (cover > RS_LOOK_MAX_COVER)
            r = rs_fail(err, RS_ERR_LIMIT, "look: %u stamps cover %.0f face areas, more than the %.0f allowed",
                        lk->stamp_count, cover, RS_LOOK_MAX_COVER);
    }
    if (r != RS_OK) {
        rs_look_destroy(lk);
        return r;
    }
    *out = lk;
    return RS_OK;
}

// --- replay ----------------------------------------------------------------------------------------

rs_result rs_look_apply(const rs_look *look, rs_makeup *mk, rs_makeup_range *dirty, rs_error *err)
{
    const rs_splat_cloud *cloud = rs_makeup_cloud(mk);
    float ratio = look->face_height / cloud->hdr.face_height;
    if (!(ratio > 0.9f && ratio < 1.1f))
        return rs_fail(err, RS_ERR_ARG, "look: made on a face of height %g, this face is %g: another face?",
                       look->face_height, cloud->hdr.face_height);
    rs_makeup_reset(mk, dirty);
    for (uint32_t i = 0; i < look->stamp_count; i++) {
        const rs_makeup_applied *s = &look->stamps[i];
        if (s->stroke_start) rs_makeup_begin_stroke(mk);
        // Amount is the intensity after the pressure map: replay it as the opacity with the map off,
        // which multiplies by exactly 1.
        rs_makeup_stamp_desc d = {
            .pos = {s->pos[0], s->pos[1], s->pos[2]},
            .view_dir = {s->view_dir[0], s->view_dir[1], s->view_dir[2]},
            .radius = s->radius,
            .opacity = s->amount,
            .pressure = 1.0f,
            .pressure_map = RS_MAKEUP_PRESSURE_NONE,
            .cosmetic = s->eraser ? NULL : &look->cosmetics[s->cosmetic],
            .eraser = s->eraser,
            .region_mask = s->region_mask,
        };
        rs_result r = rs_makeup_stamp(mk, &d, NULL, err);
        if (r != RS_OK) {
            rs_makeup_reset(mk, dirty);
            return r;
        }
    }
    rs_makeup_forget_history(mk);  // also closes the last stroke
    return RS_OK;
}

rs_result rs_look_read(const char *path, rs_look **out, rs_error *err)
{
    *out = NULL;
    void *data = NULL;
    size_t len = 0;
    rs_result r = rs_file_read_all(path, RS_LOOK_MAX_BYTES, &data, &len, err);
    if (r != RS_OK) return r;
    rs_error inner = {0};
    r = rs_look_parse(data, len, out, &inner);
    free(data);
    return r != RS_OK ? rs_fail(err, r, "%s: %s", path, inner.msg) : RS_OK;
}

rs_result rs_look_load(rs_makeup *mk, const char *path, rs_makeup_range *dirty, rs_error *err)
{
    if (dirty) *dirty = (rs_makeup_range){0, 0};
    rs_look *look = NULL;
    rs_result r = rs_look_read(path, &look, err);
    if (r != RS_OK) return r;
    rs_error inner = {0};
    r = rs_look_apply(look, mk, dirty, &inner);
    rs_look_destroy(look);
    if (r != RS_OK) return rs_fail(err, r, "%s: %s", path, inner.msg);
    return RS_OK;
}

// --- writing ---------------------------------------------------------------------------------------

rs_result rs_look_write_memory(const rs_makeup *mk, char **out, size_t *out_len, rs_error *err)
{
    uint32_t n = rs_makeup_log_count(mk), nc = rs_makeup_log_cosmetic_count(mk);
    const rs_makeup_applied *st = rs_makeup_log_stamps(mk);
    rs_text_writer w = {0};
    // Only the cosmetics the stamps use (not those of undone or cleared strokes), renumbered in order
    // of first use, so the same layer always writes the same text.
    uint32_t *remap = malloc(((size_t)nc + 1) * sizeof *remap);
    if (!remap) {
        return rs_fail(err, RS_ERR_NOMEM, "look: writing %u stamps: out of memory", n);
    }
    for (uint32_t i = 0; i < nc; i++) remap[i] = UINT32_MAX;
#define PUT(...) rs_text_printf(&w, __VA_ARGS__)
    PUT("rouge-look %d\n# %u stamps in model space; docs/makeup.md\n", RS_LOOK_VERSION, n);
    PUT("face height=%.9g\n", rs_makeup_cloud(mk)->hdr.face_height);
    uint32_t used = 0;
    for (uint32_t i = 0; i < n; i++) {
        if (st[i].eraser || remap[st[i].cosmetic] != UINT32_MAX) continue;
        char c[512];
        rs_cosmetic_format(rs_makeup_log_cosmetic(mk, st[i].cosmetic), c, sizeof c);
        remap[st[i].cosmetic] = used;
        PUT("cosmetic %u %s\n", used++, c);
    }
    for (uint32_t i = 0; i < n; i++) {
        const rs_makeup_applied *s = &st[i];
        if (s->stroke_start) PUT("%sstroke\n", i ? "end\n" : "");
        PUT("%c %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g", s->eraser ? 'e' : 'p', s->pos[0], s->pos[1], s->pos[2],
            s->view_dir[0], s->view_dir[1], s->view_dir[2], s->radius, s->amount);
        if (s->eraser) PUT("\n");
        else PUT(" %u%s\n", remap[s->cosmetic], s->region_mask ? " mask" : "");
    }
    if (n) PUT("end\n");
#undef PUT
    free(remap);
    return rs_text_writer_finish(&w, "look", out, out_len, err);
}

rs_result rs_look_save(const rs_makeup *mk, const char *path, rs_error *err)
{
    char *text = NULL;
    size_t len = 0;
    rs_result r = rs_look_write_memory(mk, &text, &len, err);
    if (r != RS_OK) return r;
    r = rs_file_write_atomic(path, text, len, err);
    free(text);
    return r;
}
