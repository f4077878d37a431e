// viewer_editor.c — the product editor: a panel (C, or the swatch row's "Edit" chip) that turns the selected
// product into a custom one: colour from a saturation/value square and a hue strip (or typed as hex: X),
// finish matte / satin / gloss / shimmer (N cycles), coverage sheer to opaque (, and .). The brush paints
// with it at once; looks carry it with the strokes it painted (docs/makeup.md).
#include "viewer_internal.h"

#include <GLFW/glfw3.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define ID_BASE 5200

void vw_editor_layout_compute(const rs_ui_toolbar_layout *tb, float s, vw_editor_layout *out)
{
    float pad = 12 * s, col = 150 * s, side = 84 * s;
    float w = 2 * pad + col + 12 * s + side;
    float h = 44 * s + 100 * s + 8 * s + 16 * s + 12 * s + 28 * s + 12 * s + 16 * s + 30 * s + 16 * s + 28 * s + pad;
    // Top right, under the environment chips and left of the right rail: the lips and the far cheek,
    // where most products go, stay clear in the default view.
    float x = tb->right.x - 12 * s - w, y = tb->top.y + tb->top.h + 54 * s;
    vw_editor_layout l = {.panel = {x, y, w, h}};
    l.close = (rs_ui_rect){x + w - pad - 28 * s, y + 8 * s, 28 * s, 28 * s};
    l.sv = (rs_ui_rect){x + pad, y + 44 * s, col, 100 * s};
    l.hue = (rs_ui_rect){x + pad, l.sv.y + l.sv.h + 8 * s, col, 16 * s};
    l.swatch = (rs_ui_rect){l.sv.x + col + 12 * s, l.sv.y, side, side * 0.75f};
    l.hex = (rs_ui_rect){l.swatch.x, l.swatch.y + l.swatch.h + 8 * s, side, 26 * s};
    float fy = l.hue.y + l.hue.h + 12 * s, fw = (w - 2 * pad - 3 * 4 * s) / 4;
    for (int i = 0; i < RS_FINISH_COUNT; i++)
        l.finish[i] = (rs_ui_rect){x + pad + (float)i * (fw + 4 * s), fy, fw, 28 * s};
    l.coverage = (rs_ui_rect){x + pad, fy + 28 * s + 12 * s + 16 * s, w - 2 * pad, 30 * s};
    // My shades: a row of swatches under the coverage, "+" at its end keeps the product shown.
    float sy = l.coverage.y + l.coverage.h + 16 * s, sw = (w - 2 * pad - VW_SHADES_MAX * 4 * s) / (VW_SHADES_MAX + 1);
    for (int i = 0; i < VW_SHADES_MAX; i++) l.shades[i] = (rs_ui_rect){x + pad + (float)i * (sw + 4 * s), sy, sw, 28 * s};
    l.shade_add = (rs_ui_rect){x + pad + VW_SHADES_MAX * (sw + 4 * s), sy, sw, 28 * s};
    *out = l;
}

const rs_cosmetic *vw_current_cosmetic(const vw_viewer *v)
{
    return v->editor.custom ? &v->editor.product : rs_cosmetic_get((uint32_t)v->cosmetic);
}

// The editor shows the product the brush holds; a preset picked while it is open is shown as it is.
void vw_editor_sync(vw_viewer *v)
{
    vw_editor *e = &v->editor;
    if (e->custom) return;
    e->product = *rs_cosmetic_get((uint32_t)v->cosmetic);
    rs_cosmetic_rgb_to_hsv(e->product.rgb, &e->hsv[0], &e->hsv[1], &e->hsv[2]);
}

// An edit turns the preset into a custom product of the same kind (it keeps its region and brush).
static void edited(vw_viewer *v)
{
    vw_editor *e = &v->editor;
    if (!e->custom) {
        const rs_cosmetic *base = rs_cosmetic_get((uint32_t)v->cosmetic);
        char name[RS_COSMETIC_NAME_MAX];
        snprintf(name, sizeof name, "custom_%s", base->name);
        memcpy(e->product.name, name, sizeof e->product.name);
        e->product.name[sizeof e->product.name - 1] = 0;
        e->custom = true;
    }
    vw_apply_brush(v);
}

static void set_rgb_from_hsv(vw_viewer *v)
{
    vw_editor *e = &v->editor;
    uint8_t rgb[3];
    rs_cosmetic_hsv_to_rgb(e->hsv[0], e->hsv[1], e->hsv[2], rgb);
    rs_cosmetic_set_rgb(&e->product, rgb);
    edited(v);
}

void vw_editor_toggle(vw_viewer *v)
{
    vw_editor *e = &v->editor;
    e->open = !e->open;
    e->hex_entry = false;
    if (e->open) vw_editor_sync(v), v->paint_mode = true, vw_apply_brush(v);
}

static bool shades_path(const vw_viewer *v, char *path, size_t cap)
{
    return v->looks.dir[0] && snprintf(path, cap, "%s/%s", v->looks.dir, VW_SHADES_FILE) < (int)cap;
}

void vw_editor_load_shades(vw_viewer *v)
{
    vw_editor *e = &v->editor;
    char path[1100], line[1024];
    e->shade_count = 0;
    FILE *f = shades_path(v, path, sizeof path) ? fopen(path, "r") : NULL;
    if (!f) return;  // none kept yet
    int n = 0;
    while (e->shade_count < VW_SHADES_MAX && fgets(line, sizeof line, f)) {
        line[strcspn(line, "\r\n")] = 0;
        rs_error err = {0};
        if (line[0] && rs_cosmetic_parse(line, &e->shades[e->shade_count], &err) == RS_OK) e->shade_count++;
        else if (line[0]) n++;
    }
    fclose(f);
    if (n) vw_toast(v, true, "%s: %d line%s not a product, skipped", path, n, n == 1 ? "" : "s");
}

// Keeps the product shown as the newest of my shades (the oldest goes when the row is full) and rewrites
// the file (atomically: a crash leaves the old row).
static void keep_shade(vw_viewer *v)
{
    vw_editor *e = &v->editor;
    char path[1100];
    if (!shades_path(v, path, sizeof path)) {
        vw_toast(v, true, "My shades: no look library folder");
        return;
    }
    if (e->shade_count == VW_SHADES_MAX) memmove(e->shades, e->shades + 1, sizeof e->shades[0] * (VW_SHADES_MAX - 1));
    else e->shade_count++;
    e->shades[e->shade_count - 1] = e->product;
    char text[VW_SHADES_MAX * 512];
    size_t len = 0;
    for (int i = 0; i < e->shade_count; i++) {
        int k = rs_cosmetic_format(&e->shades[i], text + len, sizeof text - len - 1);
        if (k < 0 || (size_t)k >= sizeof text - len - 1) break;
        len += (size_t)k;
        text[len++] = '\n';
    }
    rs_error err = {0};
    if (rs_looklib_make_dir(v->looks.dir, &err) != RS_OK || rs_file_write_atomic(path, text, len, &err) != RS_OK)
        vw_toast(v, true, "My shades: %s", err.msg);
    else vw_toast(v, false, "Kept in my shades (%s)", path);
}

// A tap on one of my shades: the brush paints it, the editor shows it.
static void use_shade(vw_viewer *v, int i)
{
    vw_editor *e = &v->editor;
    e->product = e->shades[i];
    e->custom = true;
    rs_cosmetic_rgb_to_hsv(e->product.rgb, &e->hsv[0], &e->hsv[1], &e->hsv[2]);
    vw_apply_brush(v);
}

static bool parse_hex(const char *s, uint8_t rgb[3])
{
    if (strlen(s) != 6) return false;
    for (int k = 0; k < 3; k++) {
        unsigned x = 0;
        for (int j = 0; j < 2; j++) {
            char c = s[2 * k + j];
            int d = c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
            if (d < 0) return false;
            x = x * 16 + (unsigned)d;
        }
        rgb[k] = (uint8_t)x;
    }
    return true;
}

static void cycle_finish(vw_viewer *v, int step)
{
    rs_finish f = rs_cosmetic_finish(&v->editor.product);
    rs_cosmetic_set_finish(&v->editor.product, (rs_finish)(((int)f + step + RS_FINISH_COUNT) % RS_FINISH_COUNT));
    edited(v);
}

static void set_coverage(vw_viewer *v, float c)
{
    v->editor.product.coverage = RS_CLAMP(c, 0.0f, 1.0f);
    edited(v);
}

// The eyedropper (V): the colour of the face under the pointer, as the last frame shows it (3 x 3 pixels,
// so a pore or a fleck does not decide it), becomes the product's.
static void pick_colour(vw_viewer *v)
{
    int w = 0, h = 0;
    rouge_pick p;
    int cx = (int)(v->mx * v->render_scale), cy = (int)(v->my * v->render_scale);
    if (!v->face || !rouge_face_texture(v->face, &w, &h) || !rouge_face_pick(v->face, cx + 0.5f, cy + 0.5f, &p)) {
        vw_toast(v, true, "Eyedropper: no face under the pointer");
        return;
    }
    size_t n = (size_t)w * (size_t)h * 4;
    uint8_t *px = malloc(n);
    rouge_error err = {0};
    if (!px || rouge_face_read_rgba(v->face, px, n, &err) != ROUGE_OK) {
        free(px);
        vw_toast(v, true, "Eyedropper: %s", px ? err.msg : "out of memory");
        return;
    }
    int sum[3] = {0}, k = 0;
    for (int y = RS_MAX(cy - 1, 0); y <= RS_MIN(cy + 1, h - 1); y++)
        for (int x = RS_MAX(cx - 1, 0); x <= RS_MIN(cx + 1, w - 1); x++, k++)
            for (int c = 0; c < 3; c++) sum[c] += px[((size_t)y * w + x) * 4 + c];
    free(px);
    if (k == 0) return;
    uint8_t rgb[3] = {(uint8_t)(sum[0] / k), (uint8_t)(sum[1] / k), (uint8_t)(sum[2] / k)};
    vw_editor *e = &v->editor;
    rs_cosmetic_set_rgb(&e->product, rgb);
    rs_cosmetic_rgb_to_hsv(rgb, &e->hsv[0], &e->hsv[1], &e->hsv[2]);
    edited(v);
}

bool vw_editor_key(vw_viewer *v, int key, int mods)
{
    vw_editor *e = &v->editor;
    if (e->hex_entry) {
        // Typed digits arrive as characters (vw_editor_char); here only the keys that end the entry.
        if (key == GLFW_KEY_ENTER || key == GLFW_KEY_KP_ENTER) {
            uint8_t rgb[3];
            if (parse_hex(e->hex, rgb)) {
                rs_cosmetic_set_rgb(&e->product, rgb);
                rs_cosmetic_rgb_to_hsv(rgb, &e->hsv[0], &e->hsv[1], &e->hsv[2]);
                edited(v);
            } else {
                vw_toast(v, true, "Colour: six hex digits, like b03050 (got '%s')", e->hex);
            }
            e->hex_entry = false;
        } else if (key == GLFW_KEY_ESCAPE) {
            e->hex_entry = false;
        } else if (key == GLFW_KEY_BACKSPACE && e->hex_len > 0) {
            e->hex[--e->hex_len] = 0;
        }
        return true;
    }
    if (!e->open) return false;
    bool shift = mods & GLFW_MOD_SHIFT;
    switch (key) {
    case GLFW_KEY_X: e->hex_entry = true, e->hex_len = 0, e->hex[0] = 0; return true;
    case GLFW_KEY_V: pick_colour(v); return true;
    case GLFW_KEY_ENTER:
    case GLFW_KEY_KP_ENTER: keep_shade(v); return true;
    case GLFW_KEY_N: cycle_finish(v, shift ? -1 : 1); return true;
    case GLFW_KEY_COMMA: set_coverage(v, roundf(e->product.coverage * 10.0f - 1.0f) / 10.0f); return true;
    case GLFW_KEY_PERIOD: set_coverage(v, roundf(e->product.coverage * 10.0f + 1.0f) / 10.0f); return true;
    case GLFW_KEY_ESCAPE: e->open = false; return true;
    default: return false;
    }
}

bool vw_editor_char(vw_viewer *v, unsigned cp)
{
    vw_editor *e = &v->editor;
    if (!e->hex_entry) return false;
    bool hex = (cp >= '0' && cp <= '9') || (cp >= 'a' && cp <= 'f') || (cp >= 'A' && cp <= 'F');
    if (hex && e->hex_len < 6) e->hex[e->hex_len++] = (char)cp, e->hex[e->hex_len] = 0;
    return true;
}

static int text_scale(float s) { return RS_MAX(1, (int)floorf(s * 2 + 0.25f)); }

void vw_editor_draw(vw_viewer *v, const rs_ui_toolbar_layout *tb)
{
    vw_editor *e = &v->editor;
    if (!e->open) return;
    if (!e->custom) vw_editor_sync(v);
    float s = v->ui_scale;
    int ts = text_scale(s);
    vw_editor_layout l;
    vw_editor_layout_compute(tb, s, &l);
    rs_ui *ui = v->ui;
    rs_ui_panel(ui, l.panel, 16 * s);
    rs_ui_text(ui, l.panel.x + 12 * s, l.panel.y + 14 * s, ts, RS_UI_WHITE, e->custom ? "Custom product" : "Product");
    if (rs_ui_button(ui, ID_BASE, l.close, RS_UI_ICON_CLOSE, false)) e->open = false;

    // Saturation (across) and value (up) at this hue, drawn as a grid of small cells.
    const int cx = 24, cy = 16;
    for (int j = 0; j < cy; j++)
        for (int i = 0; i < cx; i++) {
            uint8_t c[3];
            rs_cosmetic_hsv_to_rgb(e->hsv[0], ((float)i + 0.5f) / cx, 1.0f - ((float)j + 0.5f) / cy, c);
            rs_ui_fill(ui, (rs_ui_rect){l.sv.x + l.sv.w * (float)i / cx, l.sv.y + l.sv.h * (float)j / cy,
                                        l.sv.w / cx + 0.5f, l.sv.h / cy + 0.5f},
                       0, (rs_ui_rgba){c[0], c[1], c[2], 255});
        }
    float dx, dy, px, py;
    if (rs_ui_drag(ui, ID_BASE + 1, l.sv, &dx, &dy)) {
        rs_ui_pointer(ui, &px, &py);
        e->hsv[1] = RS_CLAMP((px - l.sv.x) / l.sv.w, 0.0f, 1.0f);
        e->hsv[2] = RS_CLAMP(1.0f - (py - l.sv.y) / l.sv.h, 0.0f, 1.0f);
        set_rgb_from_hsv(v);
    }
    float mx = l.sv.x + e->hsv[1] * l.sv.w, my = l.sv.y + (1.0f - e->hsv[2]) * l.sv.h;
    rs_ui_ring(ui, mx, my, 7 * s, 2.5f * s, RS_UI_WHITE);
    rs_ui_ring(ui, mx, my, 9 * s, 1.5f * s, (rs_ui_rgba){0, 0, 0, 160});

    const int nh = 36;
    for (int i = 0; i < nh; i++) {
        uint8_t c[3];
        rs_cosmetic_hsv_to_rgb(360.0f * ((float)i + 0.5f) / nh, 1.0f, 1.0f, c);
        rs_ui_fill(ui, (rs_ui_rect){l.hue.x + l.hue.w * (float)i / nh, l.hue.y, l.hue.w / nh + 0.5f, l.hue.h}, 0,
                   (rs_ui_rgba){c[0], c[1], c[2], 255});
    }
    if (rs_ui_drag(ui, ID_BASE + 2, l.hue, &dx, &dy)) {
        rs_ui_pointer(ui, &px, &py);
        e->hsv[0] = RS_CLAMP((px - l.hue.x) / l.hue.w, 0.0f, 0.999f) * 360.0f;
        set_rgb_from_hsv(v);
    }
    float hx = l.hue.x + e->hsv[0] / 360.0f * l.hue.w;
    rs_ui_fill(ui, (rs_ui_rect){hx - 2 * s, l.hue.y - 3 * s, 4 * s, l.hue.h + 6 * s}, 2 * s, RS_UI_WHITE);

    // The product as it is, and its colour as hex (tap, or X, to type one).
    const uint8_t *rgb = e->product.rgb;
    rs_ui_fill(ui, l.swatch, 10 * s, (rs_ui_rgba){rgb[0], rgb[1], rgb[2], 255});
    rs_ui_stroke(ui, l.swatch, 10 * s, 1.5f * s, RS_UI_DIM);
    char hex[16];
    if (e->hex_entry) snprintf(hex, sizeof hex, "#%s_", e->hex);
    else snprintf(hex, sizeof hex, "#%02X%02X%02X", rgb[0], rgb[1], rgb[2]);
    if (rs_ui_text_button(ui, ID_BASE + 3, l.hex, hex, e->hex_entry)) e->hex_entry = true, e->hex_len = 0, e->hex[0] = 0;

    rs_finish f = rs_cosmetic_finish(&e->product);
    static const char *const labels[RS_FINISH_COUNT] = {"Matte", "Satin", "Gloss", "Shimmer"};
    for (int i = 0; i < RS_FINISH_COUNT; i++)
        if (rs_ui_text_button(ui, ID_BASE + 10 + i, l.finish[i], labels[i], (int)f == i) && (int)f != i) {
            rs_cosmetic_set_finish(&e->product, (rs_finish)i);
            edited(v);
        }
    float cov = e->product.coverage;
    char cov_text[32];
    snprintf(cov_text, sizeof cov_text, "Coverage: %s", cov < 0.34f ? "sheer" : cov < 0.67f ? "medium" : "opaque");
    rs_ui_text(ui, l.coverage.x, l.coverage.y - 14 * s, RS_MAX(1, (int)floorf(s + 0.25f)), RS_UI_DIM, cov_text);
    snprintf(cov_text, sizeof cov_text, "%.0f%%", cov * 100.0f);
    if (rs_ui_slider(ui, ID_BASE + 20, l.coverage, RS_UI_ICON_DROP, NULL, cov_text, &cov)) set_coverage(v, cov);

    rs_ui_text(ui, l.shades[0].x, l.shades[0].y - 14 * s, RS_MAX(1, (int)floorf(s + 0.25f)), RS_UI_DIM,
               "My shades (Enter keeps this one)");
    for (int i = 0; i < VW_SHADES_MAX; i++) {
        if (i >= e->shade_count) {
            rs_ui_stroke(ui, l.shades[i], 6 * s, 1.0f * s, RS_UI_DIM);
            continue;
        }
        bool on = e->custom && !memcmp(e->shades[i].rgb, e->product.rgb, 3);
        if (rs_ui_swatch(ui, ID_BASE + 30 + i, l.shades[i], e->shades[i].rgb, on)) use_shade(v, i);
    }
    if (rs_ui_text_button(ui, ID_BASE + 30 + VW_SHADES_MAX, l.shade_add, "+", false)) keep_shade(v);
}
