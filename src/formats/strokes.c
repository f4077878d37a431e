// strokes.c — the stroke file (text, "rouge-strokes 1"; docs/makeup.md): parser, recorder, writer.
// The parser trusts nothing: a bounded line length, capped counts, every number checked for being
// finite and in range, one-line errors with the line number.
#define _POSIX_C_SOURCE 200809L  // strtok_r
#include "formats/strokes.h"
#include "formats/textfile.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *pressure_names[RS_MAKEUP_PRESSURE_COUNT] = {"floor", "linear", "none"};

const char *rs_strokes_pressure_name(rs_makeup_pressure p)
{
    return (unsigned)p < RS_MAKEUP_PRESSURE_COUNT ? pressure_names[p] : "unknown";
}

rs_result rs_strokes_create(rs_strokes **out, rs_error *err)
{
    rs_strokes *doc = calloc(1, sizeof *doc);
    if (!doc) return rs_fail(err, RS_ERR_NOMEM, "strokes: out of memory");
    *out = doc;
    return RS_OK;
}

void rs_strokes_destroy(rs_strokes *doc)
{
    if (!doc) return;
    free(doc->strokes);
    free(doc->samples);
    free(doc);
}

// --- validation shared by the parser and the recorder ------------------------------------------------

static bool in_range(float v, float lo, float hi) { return isfinite(v) && v >= lo && v <= hi; }

static rs_result check_view(const rs_strokes_view *v, rs_error *err)
{
    if (!in_range(v->yaw_deg, -360.0f, 360.0f))
        return rs_fail(err, RS_ERR_FORMAT, "view: yaw: %g not in [-360, 360]", v->yaw_deg);
    if (!in_range(v->pitch_deg, -90.0f, 90.0f))
        return rs_fail(err, RS_ERR_FORMAT, "view: pitch: %g not in [-90, 90]", v->pitch_deg);
    if (!in_range(v->zoom, 1e-3f, 100.0f))
        return rs_fail(err, RS_ERR_FORMAT, "view: zoom: %g not in [0.001, 100]", v->zoom);
    if (!in_range(v->pan[0], -RS_VIEW_PAN_MAX, RS_VIEW_PAN_MAX) || !in_range(v->pan[1], -RS_VIEW_PAN_MAX, RS_VIEW_PAN_MAX))
        return rs_fail(err, RS_ERR_FORMAT, "view: pan: %g,%g not in [-%g, %g]", v->pan[0], v->pan[1], RS_VIEW_PAN_MAX,
                       RS_VIEW_PAN_MAX);
    if (!in_range(v->fov_deg, RS_VIEW_FOV_MIN_DEG, RS_VIEW_FOV_MAX_DEG))
        return rs_fail(err, RS_ERR_FORMAT, "view: fov: %g not in [%g, %g]", v->fov_deg, RS_VIEW_FOV_MIN_DEG,
                       RS_VIEW_FOV_MAX_DEG);
    if (v->width_px < 1 || v->width_px > RS_STROKES_MAX_SIZE_PX || v->height_px < 1 ||
        v->height_px > RS_STROKES_MAX_SIZE_PX)
        return rs_fail(err, RS_ERR_FORMAT, "view: size: %ux%u not in 1..%d", v->width_px, v->height_px,
                       RS_STROKES_MAX_SIZE_PX);
    return RS_OK;
}

static rs_result check_brush(const rs_strokes_brush *b, rs_error *err)
{
    if (!in_range(b->size_rel, 1e-4f, 1.0f))
        return rs_fail(err, RS_ERR_FORMAT, "brush: size: %g not in [0.0001, 1]", b->size_rel);
    if (!in_range(b->opacity, 0.0f, 1.0f))
        return rs_fail(err, RS_ERR_FORMAT, "brush: opacity: %g not in [0, 1]", b->opacity);
    if ((unsigned)b->pressure >= RS_MAKEUP_PRESSURE_COUNT)
        return rs_fail(err, RS_ERR_FORMAT, "brush: pressure: unknown map");
    if ((unsigned)b->tool >= RS_TOOL_COUNT) return rs_fail(err, RS_ERR_FORMAT, "brush: tool: unknown tool %d", (int)b->tool);
    if (b->tool != RS_TOOL_PAINT && b->eraser)
        return rs_fail(err, RS_ERR_FORMAT, "brush: tool: %s with eraser=1 (the eraser is a paint tool)",
                       rs_paint_tool_name(b->tool));
    return RS_OK;
}

static rs_result check_sample(const rs_strokes_sample *s, const rs_strokes_sample *prev, rs_error *err)
{
    if (!in_range(s->t_s, 0.0f, 1e6f)) return rs_fail(err, RS_ERR_FORMAT, "sample: time: %g not in [0, 1e6] s", s->t_s);
    if (prev && s->t_s < prev->t_s)
        return rs_fail(err, RS_ERR_FORMAT, "sample: time: %g goes back (previous %g)", s->t_s, prev->t_s);
    if (!in_range(s->x_px, -RS_STROKES_MAX_COORD, RS_STROKES_MAX_COORD) ||
        !in_range(s->y_px, -RS_STROKES_MAX_COORD, RS_STROKES_MAX_COORD))
        return rs_fail(err, RS_ERR_FORMAT, "sample: position: (%g, %g) not finite or beyond %g px", s->x_px, s->y_px,
                       RS_STROKES_MAX_COORD);
    if (!in_range(s->pressure, 0.0f, 1.0f))
        return rs_fail(err, RS_ERR_FORMAT, "sample: pressure: %g not in [0, 1]", s->pressure);
    return RS_OK;
}

// --- recording -----------------------------------------------------------------------------------

rs_result rs_strokes_begin(rs_strokes *doc, const rs_strokes_view *view, const rs_strokes_brush *brush,
                           const rs_cosmetic *cosmetic, rs_error *err)
{
    rs_result r;
    if ((r = check_view(view, err)) != RS_OK || (r = check_brush(brush, err)) != RS_OK ||
        (r = rs_cosmetic_validate(cosmetic, err)) != RS_OK)
        return r;
    if (doc->open) rs_strokes_end(doc);
    if (doc->count >= RS_STROKES_MAX_STROKES)
        return rs_fail(err, RS_ERR_LIMIT, "strokes: more than %d strokes", RS_STROKES_MAX_STROKES);
    if (!rs_array_grow((void **)&doc->strokes, &doc->stroke_cap, doc->count + 1, sizeof *doc->strokes))
        return rs_fail(err, RS_ERR_NOMEM, "strokes: out of memory");
    doc->strokes[doc->count++] = (rs_strokes_stroke){*view, *brush, *cosmetic, doc->sample_count, 0};
    doc->open = true;
    return RS_OK;
}

rs_result rs_strokes_add_sample(rs_strokes *doc, const rs_strokes_sample *sample, rs_error *err)
{
    if (!doc->open) return rs_fail(err, RS_ERR_FORMAT, "sample: outside a stroke");
    rs_strokes_stroke *st = &doc->strokes[doc->count - 1];
    rs_result r = check_sample(sample, st->sample_count ? &doc->samples[doc->sample_count - 1] : NULL, err);
    if (r != RS_OK) return r;
    if (doc->sample_count >= RS_STROKES_MAX_SAMPLES)
        return rs_fail(err, RS_ERR_LIMIT, "sample: more than %u samples in the file", RS_STROKES_MAX_SAMPLES);
    if (!rs_array_grow((void **)&doc->samples, &doc->sample_cap, doc->sample_count + 1, sizeof *doc->samples))
        return rs_fail(err, RS_ERR_NOMEM, "strokes: out of memory");
    doc->samples[doc->sample_count++] = *sample;
    st->sample_count++;
    return RS_OK;
}

void rs_strokes_end(rs_strokes *doc)
{
    if (!doc->open) return;
    doc->open = false;
    if (doc->strokes[doc->count - 1].sample_count == 0) doc->count--;
}

void rs_strokes_drop_open(rs_strokes *doc)
{
    if (!doc->open) return;
    doc->open = false;
    doc->sample_count = doc->strokes[--doc->count].first_sample;
}

// --- parsing -----------------------------------------------------------------------------------------

typedef struct parser {
    rs_strokes *doc;
    uint32_t line;
    rs_error *err;
    rs_strokes_view view;
    rs_strokes_brush brush;
    rs_cosmetic cosmetic;
    bool have_view, have_brush, have_cosmetic;
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

// Re-labels an error from the shared checks with the line number.
static rs_result relabel(parser *p, rs_result r, const rs_error *inner)
{
    return rs_fail(p->err, r, "line %u: %s", p->line, inner->msg);
}

// Splits "key=value"; false when there is no '='.
static bool split_kv(char *tok, char **key, char **val)
{
    char *eq = strchr(tok, '=');
    if (!eq) return false;
    *eq = '\0';
    *key = tok;
    *val = eq + 1;
    return true;
}

static int key_index(const char *key, const char *const *keys, int n)
{
    for (int k = 0; k < n; k++)
        if (strcmp(key, keys[k]) == 0) return k;
    return -1;
}

static rs_result parse_view(parser *p, char **save)
{
    // pan is optional (files written before it have none: unpanned).
    static const char *const keys[] = {"yaw", "pitch", "zoom", "fov", "size", "pan"};
    bool seen[6] = {false};
    rs_strokes_view v = {0};
    char *tok, *key, *val;
    while ((tok = strtok_r(NULL, " \t", save)) != NULL) {
        if (!split_kv(tok, &key, &val)) return perr(p, "view: '%.64s' is not key=value", tok);
        int k = key_index(key, keys, 6);
        if (k < 0) return perr(p, "view: unknown key '%.32s'", key);
        if (seen[k]) return perr(p, "view: %s given twice", key);
        seen[k] = true;
        bool ok;
        if (k == 5) {
            char *c = strchr(val, ',');
            ok = c != NULL;
            if (ok) {
                *c = '\0';
                ok = rs_parse_float(val, &v.pan[0]) && rs_parse_float(c + 1, &v.pan[1]);
            }
        } else if (k == 4) {
            char *x = strchr(val, 'x');
            ok = x != NULL;
            if (ok) {
                *x = '\0';
                ok = rs_text_parse_uint(val, RS_STROKES_MAX_SIZE_PX, &v.width_px) &&
                     rs_text_parse_uint(x + 1, RS_STROKES_MAX_SIZE_PX, &v.height_px);
            }
        } else {
            float *f[] = {&v.yaw_deg, &v.pitch_deg, &v.zoom, &v.fov_deg};
            ok = rs_parse_float(val, f[k]);
        }
        if (!ok) return perr(p, "view: %s: bad value '%.64s'", key, val);
    }
    for (int k = 0; k < 5; k++)
        if (!seen[k]) return perr(p, "view: missing %s=", keys[k]);
    rs_error inner = {0};
    rs_result r = check_view(&v, &inner);
    if (r != RS_OK) return relabel(p, r, &inner);
    p->view = v;
    p->have_view = true;
    return RS_OK;
}

static rs_result parse_brush(parser *p, char **save)
{
    // tool is optional (files written before it have none: paint).
    static const char *const keys[] = {"size", "opacity", "pressure", "mirror", "eraser", "mask", "tool"};
    bool seen[7] = {false};
    rs_strokes_brush b = {0};
    char *tok, *key, *val;
    while ((tok = strtok_r(NULL, " \t", save)) != NULL) {
        if (!split_kv(tok, &key, &val)) return perr(p, "brush: '%.64s' is not key=value", tok);
        int k = key_index(key, keys, 7);
        if (k < 0) return perr(p, "brush: unknown key '%.32s'", key);
        if (seen[k]) return perr(p, "brush: %s given twice", key);
        seen[k] = true;
        bool ok;
        uint32_t flag = 0;
        if (k == 0) {
            ok = rs_parse_float(val, &b.size_rel);
        } else if (k == 1) {
            ok = rs_parse_float(val, &b.opacity);
        } else if (k == 2) {
            int m = key_index(val, pressure_names, RS_MAKEUP_PRESSURE_COUNT);
            ok = m >= 0;
            if (ok) b.pressure = (rs_makeup_pressure)m;
        } else if (k == 6) {
            ok = rs_paint_tool_parse(val, &b.tool);
            if (!ok) return perr(p, "brush: tool: '%.32s' is not a tool (paint, smudge, blend)", val);
        } else {
            ok = rs_text_parse_uint(val, 1, &flag);
            if (k == 3) b.mirror = flag;
            else if (k == 4) b.eraser = flag;
            else b.any_region = !flag;
        }
        if (!ok) return perr(p, "brush: %s: bad value '%.64s'", key, val);
    }
    if (!seen[0] || !seen[1]) return perr(p, "brush: needs size= and opacity=");
    rs_error inner = {0};
    rs_result r = check_brush(&b, &inner);
    if (r != RS_OK) return relabel(p, r, &inner);
    p->brush = b;
    p->have_brush = true;
    return RS_OK;
}

static rs_result parse_sample(parser *p, char **save)
{
    float v[4];
    for (int k = 0; k < 4; k++) {
        char *tok = strtok_r(NULL, " \t", save);
        if (!tok) return perr(p, "sample: needs 4 numbers (t x y pressure), got %d", k);
        if (!rs_parse_float(tok, &v[k])) return perr(p, "sample: value %d: '%.64s' is not a finite number", k + 1, tok);
    }
    if (strtok_r(NULL, " \t", save)) return perr(p, "sample: more than 4 numbers");
    rs_strokes_sample s = {v[0], v[1], v[2], v[3]};
    rs_error inner = {0};
    rs_result r = rs_strokes_add_sample(p->doc, &s, &inner);
    if (r != RS_OK) return relabel(p, r, &inner);
    return RS_OK;
}

static rs_result parse_line(parser *p, char *line, char **save)
{
    char *kw = strtok_r(line, " \t", save);
    if (strcmp(kw, "s") == 0) {
        if (!p->doc->open) return perr(p, "sample outside a stroke (missing 'stroke')");
        return parse_sample(p, save);
    }
    if (strcmp(kw, "end") == 0) {
        if (!p->doc->open) return perr(p, "'end' without 'stroke'");
        if (strtok_r(NULL, " \t", save)) return perr(p, "end: unexpected text");
        if (p->doc->strokes[p->doc->count - 1].sample_count == 0) return perr(p, "stroke has no samples");
        rs_strokes_end(p->doc);
        return RS_OK;
    }
    if (p->doc->open) return perr(p, "'%.32s' inside a stroke (missing 'end')", kw);
    if (strcmp(kw, "view") == 0) return parse_view(p, save);
    if (strcmp(kw, "brush") == 0) return parse_brush(p, save);
    if (strcmp(kw, "cosmetic") == 0) {
        char *rest = strtok_r(NULL, "", save);
        rs_error inner = {0};
        if (!rest) return perr(p, "cosmetic: missing name");
        rs_result r = rs_cosmetic_parse(rest, &p->cosmetic, &inner);
        if (r != RS_OK) return relabel(p, r, &inner);
        p->have_cosmetic = true;
        return RS_OK;
    }
    if (strcmp(kw, "stroke") == 0) {
        if (strtok_r(NULL, " \t", save)) return perr(p, "stroke: unexpected text");
        if (!p->have_view || !p->have_brush || !p->have_cosmetic)
            return perr(p, "stroke: needs a view, brush and cosmetic line before it");
        rs_error inner = {0};
        rs_result r = rs_strokes_begin(p->doc, &p->view, &p->brush, &p->cosmetic, &inner);
        if (r != RS_OK) return relabel(p, r, &inner);
        return RS_OK;
    }
    return perr(p, "unknown keyword '%.32s'", kw);
}

rs_result rs_strokes_parse(const void *data, size_t len, rs_strokes **out, rs_error *err)
{
    if (len > RS_STROKES_MAX_BYTES)
        return rs_fail(err, RS_ERR_LIMIT, "strokes: %zu bytes, more than %u", len, RS_STROKES_MAX_BYTES);
    rs_strokes *doc = NULL;
    rs_result r = rs_strokes_create(&doc, err);
    if (r != RS_OK) return r;
    parser p = {.doc = doc, .err = err};
    rs_text_reader t = {.data = data, .len = len};
    bool header = false;
    char buf[RS_STROKES_MAX_LINE + 1], *line;
    while (r == RS_OK && rs_text_next_line(&t, buf, sizeof buf, &line, &r, err)) {
        p.line = t.line;
        if (!header) {
            r = rs_text_check_header(line, "rouge-strokes", RS_STROKES_VERSION, "stroke file", t.line, err);
            header = true;
            continue;
        }
        char *save = NULL;
        r = parse_line(&p, line, &save);
    }
    if (r == RS_OK && !header) r = rs_fail(err, RS_ERR_FORMAT, "strokes: empty file (no 'rouge-strokes' line)");
    if (r == RS_OK && doc->open)
        r = rs_fail(err, RS_ERR_FORMAT, "line %u: file ends inside a stroke (missing 'end')", p.line);
    if (r != RS_OK) {
        rs_strokes_destroy(doc);
        return r;
    }
    *out = doc;
    return RS_OK;
}

rs_result rs_strokes_load(const char *path, rs_strokes **out, rs_error *err)
{
    void *data = NULL;
    size_t len = 0;
    rs_result r = rs_file_read_all(path, RS_STROKES_MAX_BYTES, &data, &len, err);
    if (r != RS_OK) return r;
    rs_error inner = {0};
    r = rs_strokes_parse(data, len, out, &inner);
    free(data);
    if (r != RS_OK) return rs_fail(err, r, "%s: %s", path, inner.msg);
    return RS_OK;
}

// --- writing -------------------------------------------------------------------------------------

rs_result rs_strokes_write_memory(const rs_strokes *doc, char **out, size_t *out_len, rs_error *err)
{
    rs_text_writer b = {0};
    rs_text_printf(&b, "rouge-strokes %d\n", RS_STROKES_VERSION);
    const rs_strokes_stroke *prev = NULL;
    for (uint32_t i = 0; i < doc->count; i++) {
        const rs_strokes_stroke *s = &doc->strokes[i];
        const rs_strokes_view *v = &s->view;
        const rs_strokes_brush *br = &s->brush;
        if (!prev || memcmp(v, &prev->view, sizeof *v) != 0) {
            rs_text_printf(&b, "view yaw=%.9g pitch=%.9g zoom=%.9g fov=%.9g size=%ux%u", v->yaw_deg, v->pitch_deg,
                      v->zoom, v->fov_deg, v->width_px, v->height_px);
            if (v->pan[0] != 0 || v->pan[1] != 0) rs_text_printf(&b, " pan=%.9g,%.9g", v->pan[0], v->pan[1]);
            rs_text_printf(&b, "\n");
        }
        if (!prev || br->size_rel != prev->brush.size_rel || br->opacity != prev->brush.opacity ||
            br->pressure != prev->brush.pressure || br->mirror != prev->brush.mirror ||
            br->eraser != prev->brush.eraser || br->any_region != prev->brush.any_region || br->tool != prev->brush.tool) {
            rs_text_printf(&b, "brush size=%.9g opacity=%.9g pressure=%s mirror=%d eraser=%d mask=%d", br->size_rel,
                      br->opacity, rs_strokes_pressure_name(br->pressure), br->mirror, br->eraser, !br->any_region);
            rs_text_printf(&b, br->tool != RS_TOOL_PAINT ? " tool=%s\n" : "\n", rs_paint_tool_name(br->tool));
        }
        if (!prev || !rs_cosmetic_equal(&s->cosmetic, &prev->cosmetic)) {
            char c[512];
            rs_cosmetic_format(&s->cosmetic, c, sizeof c);
            rs_text_printf(&b, "cosmetic %s\n", c);
        }
        rs_text_printf(&b, "stroke\n");
        for (uint32_t k = 0; k < s->sample_count; k++) {
            const rs_strokes_sample *sm = &doc->samples[s->first_sample + k];
            rs_text_printf(&b, "s %.9g %.9g %.9g %.9g\n", sm->t_s, sm->x_px, sm->y_px, sm->pressure);
        }
        rs_text_printf(&b, "end\n");
        prev = s;
    }
    return rs_text_writer_finish(&b, "strokes", out, out_len, err);
}

rs_result rs_strokes_save(const rs_strokes *doc, const char *path, rs_error *err)
{
    char *text = NULL;
    size_t len = 0;
    rs_result r = rs_strokes_write_memory(doc, &text, &len, err);
    if (r != RS_OK) return r;
    r = rs_file_write_atomic(path, text, len, err);
    free(text);
    return r;
}
