// viewer_draw.c — what the viewer draws: the picture (and the split's bare half), the toolbar with its
// state, the split divider, the brush ring, HUD, toasts, the help overlay and the loading screen; and
// screenshots of the window. Actions on what is tapped live in viewer.c.
#define _POSIX_C_SOURCE 200809L
#include "viewer_internal.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <ctype.h>
#include <math.h>
#include <string.h>

// "lipstick_satin" -> "Lipstick satin"
static void display_name(const char *name, char *out, size_t n)
{
    snprintf(out, n, "%s", name);
    for (char *p = out; *p; p++)
        if (*p == '_') *p = ' ';
    out[0] = (char)toupper((unsigned char)out[0]);
}

void vw_draw_picture(vw_viewer *v, rs_ui *ui)
{
    int tw = 0, th = 0;
    GLuint tex = v->face ? rouge_face_texture(v->face, &tw, &th) : 0;
    rs_ui_rect full = {0, 0, (float)v->fb_w, (float)v->fb_h};
    // Background in the renderer's colour while nothing is rendered yet (loading).
    const float *bg = v->view.background;
    rs_ui_fill(ui, full, 0, (rs_ui_rgba){(uint8_t)(bg[0] * 255), (uint8_t)(bg[1] * 255), (uint8_t)(bg[2] * 255), 255});
    if (!tex) return;
    // Rendered textures have GL's bottom-first rows: the rect's top samples v = 1.
    static const float uv_full[4] = {0, 1, 1, 0};
    rs_ui_image(ui, tex, full, uv_full);
    if (v->split && v->before.tex) {
        float sx = floorf(v->split_frac * (float)v->fb_w);
        float uv[4] = {0, 1, sx / (float)v->fb_w, 0};
        rs_ui_image(ui, v->before.tex, (rs_ui_rect){0, 0, sx, (float)v->fb_h}, uv);
    }
}

// The before/after divider: a line with a round handle on the picture's bottom edge, just above the
// swatch sheet, and "Before" and "After" (or the compared look's name and "Current") in the bottom
// corners: all of it clear of the face's centre, where finishes are compared (beside the handle the
// labels once sat on the lips).
static void draw_split_divider(vw_viewer *v, const rs_ui_toolbar_layout *l)
{
    float s = v->ui_scale, sx = floorf(v->split_frac * (float)v->fb_w), hr = 22 * s;
    float hy = floorf(l->bottom.y - hr - 4 * s);
    rs_ui_line(v->ui, sx, 0, sx, (float)v->fb_h, 2.5f * s, (rs_ui_rgba){255, 255, 255, 220});
    float dx, dy;
    // The whole line is draggable, the handle just shows where.
    if (rs_ui_drag(v->ui, 3001, (rs_ui_rect){sx - hr, hy - hr, 2 * hr, 2 * hr}, &dx, &dy) ||
        rs_ui_drag(v->ui, 3003, (rs_ui_rect){sx - 8 * s, 0, 16 * s, (float)v->fb_h}, &dx, &dy))
        v->split_frac = RS_CLAMP(v->split_frac + dx / (float)v->fb_w, 0.02f, 0.98f);
    rs_ui_circle(v->ui, sx, hy + 2 * s, hr + 2 * s, (rs_ui_rgba){0, 0, 0, 80});
    rs_ui_circle(v->ui, sx, hy, hr, RS_UI_WHITE);
    rs_ui_icon_draw(v->ui, RS_UI_ICON_CHEVRONS, (rs_ui_rect){sx - hr * 0.6f, hy - hr * 0.6f, hr * 1.2f, hr * 1.2f},
                    (rs_ui_rgba){40, 40, 48, 255});
    int ts = RS_MAX(1, (int)(s * 2 + 0.25f));
    // Left: the bare face, or the look from the library being compared; right: the look being painted.
    bool cmp = vw_looks_comparing(v);
    const char *left = cmp ? v->looks.compare : "Before", *right = cmp ? "Current" : "After";
    float lw = rs_ui_text_width(left, ts), rw = rs_ui_text_width(right, ts), th = 7.0f * (float)ts;
    float ph = th + 14 * s, py = l->bottom.y - ph - 6 * s;
    rs_ui_rect lr = {l->left.x + l->left.w + 8 * s, py, lw + 20 * s, ph};
    rs_ui_rect rr = {l->right.x - 8 * s - rw - 20 * s, py, rw + 20 * s, ph};
    rs_ui_fill(v->ui, lr, ph * 0.5f, RS_UI_PANEL);
    rs_ui_text(v->ui, lr.x + 10 * s, py + (ph - th) * 0.5f, ts, RS_UI_WHITE, left);
    rs_ui_fill(v->ui, rr, ph * 0.5f, RS_UI_PANEL);
    rs_ui_text(v->ui, rr.x + 10 * s, py + (ph - th) * 0.5f, ts, RS_UI_WHITE, right);
}

// The brush ring: the brush's footprint on the face under the cursor (its size at that depth).
static void draw_brush_ring(vw_viewer *v)
{
    if (v->ui_input_only || !v->paint_mode || !v->face || v->pointer_outside || v->scene_owns[1] || v->scene_owns[2] ||
        rs_ui_captures(v->ui, v->mx, v->my))
        return;
    if (v->ring_moved && !v->scene_owns[0]) {
        // One pick per frame at most, and only when the cursor moved.
        rouge_pick pk;
        v->ring_valid = false;
        if (vw_pick(v, v->mx, v->my, &pk)) {
            float r = pk.brush_radius_px;
            if (isfinite(r) && r > 0) v->ring_px = r, v->ring_valid = true;
        }
        v->ring_moved = false;
    }
    if (!v->ring_valid) return;
    float s = v->ui_scale;
    rs_ui_ring(v->ui, v->mx, v->my, v->ring_px, 3.0f * s, (rs_ui_rgba){0, 0, 0, 90});
    rs_ui_ring(v->ui, v->mx, v->my, v->ring_px, 1.5f * s, v->eraser ? RS_UI_WHITE : RS_UI_ACCENT);
    rs_ui_circle(v->ui, v->mx, v->my, 1.5f * s, RS_UI_WHITE);
}

static void draw_hud(vw_viewer *v, const rs_ui_toolbar_layout *l)
{
    if (!v->hud || !v->face) return;
    float s = v->ui_scale;
    const rouge_stats *st = &v->info;
    uint32_t total = st->splats;
    uint32_t drawn = st->splats_drawn ? st->splats_drawn : (v->rendered.max_splats ? v->rendered.max_splats : total);
    int level = 0;
    for (uint32_t i = 0; i < st->lod_count; i++)
        if (st->lods[i] >= drawn) level = (int)i;
    char lines[4][96];
    snprintf(lines[0], sizeof lines[0], "%.1f ms  %.0f fps", v->frame_ms_avg, v->frame_ms_avg > 0 ? 1000.0 / v->frame_ms_avg : 0.0);
    snprintf(lines[1], sizeof lines[1], "LOD %d/%u  %uk of %uk splats", level, st->lod_count,
             (drawn + 500) / 1000, (total + 500) / 1000);
    snprintf(lines[2], sizeof lines[2], "%s K=%d  %dx%d",
             v->view.pipeline == ROUGE_PIPELINE_REFERENCE ? "reference" : "mobile", st->kernel_count, v->view.width,
             v->view.height);
    snprintf(lines[3], sizeof lines[3], "%s", v->rendered_full ? "full quality" : "interactive");
    // The HUD is for developers: the small font keeps it off the face.
    int ts = RS_MAX(1, (int)(s + 0.25f));
    float lh = 11.0f * (float)ts, w = 0;
    for (int i = 0; i < 4; i++) w = RS_MAX(w, rs_ui_text_width(lines[i], ts));
    rs_ui_rect r = {l->left.x + l->left.w + 8 * s, l->top.y + l->top.h + 8 * s, w + 16 * s, 4 * lh + 10 * s};
    rs_ui_fill(v->ui, r, 8 * s, (rs_ui_rgba){15, 15, 18, 170});
    for (int i = 0; i < 4; i++)
        rs_ui_text(v->ui, r.x + 8 * s, r.y + 6 * s + (float)i * lh, ts, i == 3 && !v->rendered_full ? RS_UI_ACCENT : RS_UI_WHITE,
                   lines[i]);
}

static void draw_toast(vw_viewer *v, const rs_ui_toolbar_layout *l)
{
    if (!v->toast[0] || vw_now() > v->toast_until) return;
    float s = v->ui_scale;
    int ts = RS_MAX(1, (int)(s * 2 + 0.25f));
    char line[256];
    snprintf(line, sizeof line, "%s", v->toast);
    // Long messages (file errors) are cut to the window.
    size_t max_chars = (size_t)RS_MAX(8.0f, ((float)v->fb_w - 80 * s) / (float)(RS_UI_FONT_CELL_W * ts));
    if (strlen(line) > max_chars) line[max_chars - 3] = '.', line[max_chars - 2] = '.', line[max_chars - 1] = '.', line[max_chars] = 0;
    float w = rs_ui_text_width(line, ts) + 32 * s, h = 11.0f * (float)ts + 16 * s;
    rs_ui_rect r = {floorf(((float)v->fb_w - w) * 0.5f), l->bottom.y - h - 12 * s, w, h};
    rs_ui_shadow(v->ui, r, h * 0.5f, 14 * s, (rs_ui_rgba){0, 0, 0, 100});
    rs_ui_fill(v->ui, r, h * 0.5f, v->toast_error ? (rs_ui_rgba){150, 30, 45, 235} : (rs_ui_rgba){30, 30, 36, 235});
    rs_ui_text(v->ui, r.x + 16 * s, r.y + 8 * s + (float)ts, ts, RS_UI_WHITE, line);
}

static void draw_help(vw_viewer *v)
{
    if (!v->help) return;
    float s = v->ui_scale;
    int ts = RS_MAX(1, (int)(s * 2 + 0.25f));
    float lh = 11.0f * (float)ts + 2 * s;
    size_t n = vw_shortcut_count;
    float kw = 0, ww = 0, gap = 24 * s, pad = 24 * s;
    for (;;) {
        kw = ww = 0;
        for (size_t i = 0; i < n; i++) {
            kw = RS_MAX(kw, rs_ui_text_width(vw_shortcuts[i].keys, ts));
            ww = RS_MAX(ww, rs_ui_text_width(vw_shortcuts[i].what, ts));
        }
        // Fall back to the small font when the window is too small for the list.
        bool fits = (float)(n + 2) * lh + 2 * pad <= (float)v->fb_h - 16 * s &&
                    kw + gap + ww + 2 * pad <= (float)v->fb_w - 16 * s;
        if (fits || ts == 1) break;
        ts--, lh = 11.0f * (float)ts + 2 * s;
    }
    float w = RS_MIN(kw + gap + ww + 2 * pad, (float)v->fb_w - 16 * s), h = (float)(n + 2) * lh + 2 * pad;
    rs_ui_rect r = {floorf(((float)v->fb_w - w) * 0.5f), floorf(((float)v->fb_h - h) * 0.5f), w, h};
    rs_ui_fill(v->ui, (rs_ui_rect){0, 0, (float)v->fb_w, (float)v->fb_h}, 0, (rs_ui_rgba){0, 0, 0, 110});
    rs_ui_panel(v->ui, r, 18 * s);
    // Nearly opaque: text behind the panel (a toast) must not show through the list.
    rs_ui_fill(v->ui, r, 18 * s, (rs_ui_rgba){22, 22, 27, 200});
    float x = r.x + pad, y = r.y + pad;
    rs_ui_text(v->ui, x, y, ts, RS_UI_ACCENT, "rouge - shortcuts and gestures");
    if (rs_ui_button(v->ui, 3002, (rs_ui_rect){r.x + r.w - 52 * s, r.y + 8 * s, 44 * s, 44 * s}, RS_UI_ICON_CLOSE, false))
        v->help = false;
    y += 2 * lh;
    for (size_t i = 0; i < n; i++, y += lh) {
        rs_ui_text(v->ui, x, y, ts, RS_UI_WHITE, vw_shortcuts[i].keys);
        rs_ui_text(v->ui, x + kw + gap, y, ts, (rs_ui_rgba){200, 200, 208, 255}, vw_shortcuts[i].what);
    }
}

static void draw_loading(vw_viewer *v)
{
    float s = v->ui_scale, cx = (float)v->fb_w * 0.5f, cy = (float)v->fb_h * 0.5f;
    double t = vw_now() - v->load.t0;
    float a = (float)fmod(t * 5.0, 6.2831853);
    rs_ui_ring(v->ui, cx, cy - 20 * s, 22 * s, 4 * s, (rs_ui_rgba){255, 255, 255, 30});
    rs_ui_arc(v->ui, cx, cy - 20 * s, 22 * s, -a, -a + 1.8f, 4 * s, RS_UI_ACCENT);
    int ts = RS_MAX(1, (int)(s * 2 + 0.25f));
    char line[600];
    const char *base = strrchr(v->load.path, '/');
    rouge_stream_progress p = v->load.stream ? rouge_stream_get_progress(v->load.stream) : (rouge_stream_progress){0};
    uint32_t decoded = p.decoded, count = p.splats;
    const rouge_progress *made = &v->load.made;
    // The stages after decoding, as rouge_face_create reports them: making the face (GPU upload, makeup
    // layer, lighting), then its first picture stage by stage (seconds for a large face on a slow GPU:
    // the stages compile their shaders on first use), with a bar of the fraction done.
    if (made->stage) {
        snprintf(line, sizeof line, "Loading %s: %u splats; %s (%d of %d)", base ? base + 1 : v->load.path,
                 count, made->stage, made->step, made->steps);
        float bw = 240 * s, bh = 4 * s, bx = cx - bw * 0.5f, by = cy + 22 * s + 7.0f * (float)ts + 10 * s;
        rs_ui_fill(v->ui, (rs_ui_rect){bx, by, bw, bh}, bh * 0.5f, (rs_ui_rgba){255, 255, 255, 30});
        rs_ui_fill(v->ui, (rs_ui_rect){bx, by, bw * RS_CLAMP(made->fraction, 0.0f, 1.0f), bh}, bh * 0.5f, RS_UI_ACCENT);
    } else if (v->load.building)
        snprintf(line, sizeof line, "Loading %s: %u splats decoded in %.1f s; building the face (GPU upload, shaders)",
                 base ? base + 1 : v->load.path, count, v->load.decoded_s);
    else if (count)
        snprintf(line, sizeof line, "Loading %s  %.1f s  %u of %u splats", base ? base + 1 : v->load.path, t, decoded,
                 count);
    else
        snprintf(line, sizeof line, "Loading %s  %.1f s", base ? base + 1 : v->load.path, t);
    float w = rs_ui_text_width(line, ts);
    rs_ui_text(v->ui, cx - w * 0.5f, cy + 22 * s, ts, RS_UI_WHITE, line);
}

// The lighting environments as chips under the top bar (issue 12): a tap relights the face.
static void draw_env_chips(vw_viewer *v, const rs_ui_toolbar_layout *l)
{
    float s = v->ui_scale, h = 30 * s, pad = 6 * s, g = 4 * s;
    int n = rouge_environment_count();
    float w[8] = {0}, total = 0;
    int ts = RS_MAX(1, (int)floorf(s * 2 + 0.25f));  // rs_ui_text_button's label scale
    for (int i = 0; i < n && i < 8; i++) total += (w[i] = rs_ui_text_width(rouge_environment_name(i), ts) + 24 * s);
    total += g * (float)(n - 1) + 2 * pad;
    rs_ui_rect panel = {l->top.x + (l->top.w - total) * 0.5f, l->top.y + l->top.h + 6 * s, total, h + 2 * pad};
    rs_ui_panel(v->ui, panel, (h + 2 * pad) * 0.5f);
    float x = panel.x + pad;
    for (int i = 0; i < n && i < 8; i++) {
        const char *name = rouge_environment_name(i);
        bool on = strcmp(name, v->env_name) == 0;
        if (rs_ui_text_button(v->ui, 4100 + i, (rs_ui_rect){x, panel.y + pad, w[i], h}, name, on) && !on)
            vw_set_env(v, name);
        x += w[i] + g;
    }
}

void vw_draw_loading_frame(vw_viewer *v)
{
    rs_ui_begin(v->ui, v->fb_w, v->fb_h, v->ui_scale, &(rs_ui_input){.x = -1, .y = -1});
    draw_loading(v);
    rs_ui_end(v->ui);
}

rs_ui_tool vw_draw_ui(vw_viewer *v, rs_ui_toolbar_state *st, int *swatch)
{
    rs_ui_input in = {.x = v->mx, .y = v->my, .down = v->ui_owns[0], .pressed = v->ui_pressed,
                      .released = v->ui_released, .inside = true};
    v->ui_pressed = v->ui_released = false;
    rs_ui_begin(v->ui, v->fb_w, v->fb_h, v->ui_scale, &in);
    if (!v->face) {
        draw_loading(v);
        return RS_UI_TOOL_NONE;
    }
    if (v->load.running || v->load.building) draw_loading(v);
    // The look library's sheet and dialog are modal: the toolbar steps aside while they are up.
    if (vw_looks_modal(v)) {
        *st = (rs_ui_toolbar_state){0};
        vw_looks_draw(v);
        rs_ui_toolbar_layout l;
        rs_ui_toolbar_layout_compute(v->fb_w, v->fb_h, v->ui_scale, (int)rs_cosmetic_count(), &l);
        draw_toast(v, &l);
        return RS_UI_TOOL_NONE;
    }
    draw_brush_ring(v);

    // Swatches and names live in the viewer (static storage would be a hidden global).
    int n = RS_MIN((int)rs_cosmetic_count(), RS_UI_TOOLBAR_MAX_SWATCHES);
    for (int i = 0; i < n; i++) {
        const rs_cosmetic *c = rs_cosmetic_get((uint32_t)i);
        memcpy(v->swatch_rgb[i], c->rgb, 3);
        display_name(c->name, v->swatch_names[i], sizeof v->swatch_names[i]);
        v->swatch_name_ptr[i] = v->swatch_names[i];
    }
    // A custom product shows in its preset's place (the ring stays there; tapping it brings the preset back).
    if (v->editor.custom && v->cosmetic < n) {
        memcpy(v->swatch_rgb[v->cosmetic], v->editor.product.rgb, 3);
        snprintf(v->swatch_names[v->cosmetic], sizeof v->swatch_names[0], "Custom %s",
                 rs_cosmetic_kind_name(v->editor.product.kind));
    }
    rs_ui_toolbar_layout l;
    rs_ui_toolbar_layout_compute(v->fb_w, v->fb_h, v->ui_scale, n, &l);
    if (v->split) draw_split_divider(v, &l);
    // The brush as a person measures it: its diameter on the face in mm, and its opacity in percent.
    snprintf(v->size_text, sizeof v->size_text, "%.0f mm", v->size_rel * v->info.face_height_mm);
    snprintf(v->opacity_text, sizeof v->opacity_text, "%.0f%%", v->opacity * 100.0f);
    *st = (rs_ui_toolbar_state){
        .swatch_count = n, .swatch_rgb = (const uint8_t(*)[3])v->swatch_rgb,
        .swatch_name = (const char *const *)v->swatch_name_ptr, .selected = v->cosmetic,
        .region_name = vw_brush_region(v),
        .size = vw_size_to_slider(v->size_rel), .opacity = v->opacity, .size_text = v->size_text,
        .opacity_text = v->opacity_text,
        .light = {v->light_dial[0], v->light_dial[1]}, .paint = v->paint_mode,
        .eraser = v->eraser && v->tool == ROUGE_TOOL_PAINT, .smudge = v->tool == ROUGE_TOOL_SMUDGE,
        .blend = v->tool == ROUGE_TOOL_BLEND,
        .mirror = v->mirror, .keep_region = !v->any_region, .split = v->split, .hud = v->hud, .help = v->help,
        .can_undo = v->info.can_undo, .can_redo = v->info.can_redo,
        .mode = v->view.mode == ROUGE_MODE_ALBEDO ? 0 : v->view.mode == ROUGE_MODE_DIFFUSE ? 1 : 2,
        .mobile = v->view.pipeline != ROUGE_PIPELINE_REFERENCE,
    };
    rs_ui_tool t = rs_ui_toolbar(v->ui, &l, st, swatch);
    // The product editor's chip at the swatch row's top right, and the editor when open.
    float s = v->ui_scale;
    rs_ui_rect chip = {l.bottom.x + l.bottom.w - 96 * s, l.bottom.y + 6 * s, 86 * s, 26 * s};
    if (rs_ui_text_button(v->ui, 5190, chip, v->editor.custom ? "Custom" : "Edit", v->editor.open))
        vw_editor_toggle(v);
    vw_editor_draw(v, &l);
    draw_env_chips(v, &l);
    draw_hud(v, &l);
    draw_toast(v, &l);
    draw_help(v);
    return t;
}

// Writes the bound framebuffer (or the region rect, window coordinates, when given) as an RGB PNG.
void vw_write_png(vw_viewer *v, const char *path, const float *rect)
{
    rs_image img = {0};
    rs_error err = {0};
    rs_result r = rs_ui_read_pixels(v->fb_w, v->fb_h, &img, &err);
    if (!r) {
        int x0 = 0, y0 = 0, w = v->fb_w, h = v->fb_h;
        if (rect && rect[2] > 0) {
            x0 = (int)lroundf(rect[0] * v->px_per_pt), y0 = (int)lroundf(rect[1] * v->px_per_pt);
            w = (int)lroundf(rect[2] * v->px_per_pt), h = (int)lroundf(rect[3] * v->px_per_pt);
            x0 = RS_CLAMP(x0, 0, v->fb_w - 1), y0 = RS_CLAMP(y0, 0, v->fb_h - 1);
            w = RS_CLAMP(w, 1, v->fb_w - x0), h = RS_CLAMP(h, 1, v->fb_h - y0);
        }
        // Crop and drop alpha in place (rows move towards the start): a screenshot is opaque RGB.
        uint8_t *d = img.pixels;
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++, d += 3) {
                const uint8_t *s = img.pixels + ((size_t)(y0 + y) * (size_t)v->fb_w + (size_t)(x0 + x)) * 4;
                d[0] = s[0], d[1] = s[1], d[2] = s[2];
            }
        img.width = w, img.height = h, img.channels = 3;
        r = rs_image_write_png(path, &img, &err);
    }
    rs_image_free(&img);
    if (r) vw_toast(v, true, "%s", err.msg);
}
