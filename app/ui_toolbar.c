// ui_toolbar.c — the makeup toolbar of ui.h: a pure layout function (tested on its own) and the drawing and
// input handling on top of the widgets in ui.c.
#include "ui.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

// Touch targets: 48 points, the common mobile guideline (Material: 48 dp; Apple: 44 pt minimum).
#define TARGET_PT 48.0f
#define MARGIN_PT 12.0f
#define GAP_PT 8.0f
#define PAD_PT 6.0f
#define SEG_W_PT 100.0f      // a render-mode segment ("Diffuse" at text scale 2 plus room)
#define PIPE_W_PT 124.0f     // "Reference" at text scale 2
#define SEP_PT 10.0f
#define LABEL_H_PT 24.0f
#define SLIDER_MAX_PT 200.0f

static const rs_ui_tool top_icons[] = {RS_UI_TOOL_SPLIT, RS_UI_TOOL_HUD, RS_UI_TOOL_SAVE,
                                       RS_UI_TOOL_LOAD, RS_UI_TOOL_SCREENSHOT, RS_UI_TOOL_HELP};
// One button for smudge and blend (it cycles): two would not fit an 800 x 600 window at full size.
static const rs_ui_tool left_tools[] = {RS_UI_TOOL_PAINT,  RS_UI_TOOL_ERASER, RS_UI_TOOL_SMUDGE, RS_UI_TOOL_MIRROR,
                                        RS_UI_TOOL_REGION, RS_UI_TOOL_UNDO,   RS_UI_TOOL_REDO,   RS_UI_TOOL_CLEAR};
#define LEFT_N ((int)RS_COUNT_OF(left_tools))

void rs_ui_toolbar_layout_compute(int fb_w, int fb_h, float scale, int swatch_count, rs_ui_toolbar_layout *out)
{
    memset(out, 0, sizeof *out);
    swatch_count = RS_CLAMP(swatch_count, 0, RS_UI_TOOLBAR_MAX_SWATCHES);
    out->swatch_count = swatch_count;
    float W = (float)fb_w, H = (float)fb_h;
    float s = scale > 0 ? scale : 1;
    // The top bar is the widest row: shrink everything when it does not fit (small windows).
    float top_w_pt = 2 * PAD_PT + 3 * SEG_W_PT + SEP_PT + PIPE_W_PT + SEP_PT + 6 * TARGET_PT;
    s = RS_MIN(s, (W - 2 * MARGIN_PT * s) / top_w_pt);
    // ... and the height must hold the top bar, the left rail and the bottom sheet.
    float h_pt = 2 * MARGIN_PT + (TARGET_PT + 2 * PAD_PT) + (2 * PAD_PT + LEFT_N * TARGET_PT + SEP_PT) +
                 (2 * PAD_PT + LABEL_H_PT + TARGET_PT) + 2 * GAP_PT;
    s = RS_MIN(s, H / h_pt);
    s = RS_MAX(s, 0.25f);
    float t = TARGET_PT * s, m = MARGIN_PT * s, g = GAP_PT * s, pad = PAD_PT * s;
    out->target = t;

    // Top bar, centred.
    float tw = top_w_pt * s, th = t + 2 * pad;
    out->top = (rs_ui_rect){floorf((W - tw) * 0.5f), m, tw, th};
    float x = out->top.x + pad, y = out->top.y + pad;
    const rs_ui_tool modes[3] = {RS_UI_TOOL_ALBEDO, RS_UI_TOOL_DIFFUSE, RS_UI_TOOL_FULL};
    for (int i = 0; i < 3; i++, x += SEG_W_PT * s) out->tool[modes[i]] = (rs_ui_rect){x, y, SEG_W_PT * s, t};
    x += SEP_PT * s;
    out->tool[RS_UI_TOOL_PIPELINE] = (rs_ui_rect){x, y, PIPE_W_PT * s, t};
    x += PIPE_W_PT * s + SEP_PT * s;
    for (size_t i = 0; i < RS_COUNT_OF(top_icons); i++, x += t) out->tool[top_icons[i]] = (rs_ui_rect){x, y, t, t};

    // Bottom sheet: the product name, then one row of swatches (narrower cells when many).
    // Whole pixels, so neighbouring swatches share an edge exactly.
    float cell = floorf(t);
    float avail = W - 2 * m - 2 * pad;
    if (swatch_count > 0 && swatch_count * cell > avail) cell = floorf(avail / (float)swatch_count);
    float bw = RS_MAX((float)swatch_count * cell, 6 * t) + 2 * pad;
    float bh = 2 * pad + LABEL_H_PT * s + t;
    out->bottom = (rs_ui_rect){floorf((W - bw) * 0.5f), H - m - bh, bw, bh};
    out->label = (rs_ui_rect){out->bottom.x + pad, out->bottom.y + pad, bw - 2 * pad, LABEL_H_PT * s};
    float sx = out->bottom.x + (bw - (float)swatch_count * cell) * 0.5f;
    float sy = out->label.y + out->label.h + (t - cell) * 0.5f;
    for (int i = 0; i < swatch_count; i++) out->swatch[i] = (rs_ui_rect){sx + (float)i * cell, sy, cell, cell};

    // Side rails fill the band between the top bar and the bottom sheet.
    float band0 = out->top.y + out->top.h + g, band1 = out->bottom.y - g;
    float lh = 2 * pad + LEFT_N * t + SEP_PT * s;
    out->left = (rs_ui_rect){m, floorf(band0 + RS_MAX(0.0f, (band1 - band0 - lh) * 0.5f)), t + 2 * pad, lh};
    y = out->left.y + pad;
    for (size_t i = 0; i < RS_COUNT_OF(left_tools); i++) {
        if (left_tools[i] == RS_UI_TOOL_UNDO) y += SEP_PT * s;
        out->tool[left_tools[i]] = (rs_ui_rect){m + pad, y, t, t};
        y += t;
    }

    // Right rail: the light dial, then the size and opacity sliders as wide as the rail (their names and
    // values sit above their tracks).
    float dial = RS_UI_DIAL_PT * s;
    float slider = RS_MIN(SLIDER_MAX_PT * s, (band1 - band0 - 2 * pad - dial - 2 * g) * 0.5f);
    slider = RS_MAX(slider, 2 * t);
    float rw = RS_MAX(t, dial) + 2 * pad, rh = 2 * pad + dial + 2 * g + 2 * slider;
    out->right = (rs_ui_rect){W - m - rw, floorf(band0 + RS_MAX(0.0f, (band1 - band0 - rh) * 0.5f)), rw, rh};
    float cx = out->right.x + rw * 0.5f;
    y = out->right.y + pad;
    out->tool[RS_UI_TOOL_LIGHT] = (rs_ui_rect){cx - dial * 0.5f, y, dial, dial};
    y += dial + g;
    out->tool[RS_UI_TOOL_SIZE] = (rs_ui_rect){out->right.x + pad, y, rw - 2 * pad, slider};
    y += slider + g;
    out->tool[RS_UI_TOOL_OPACITY] = (rs_ui_rect){out->right.x + pad, y, rw - 2 * pad, slider};
}

rs_ui_tool rs_ui_toolbar_hit(const rs_ui_toolbar_layout *l, float x, float y, int *swatch)
{
    for (int i = 0; i < l->swatch_count; i++)
        if (rs_ui_rect_contains(l->swatch[i], x, y)) {
            if (swatch) *swatch = i;
            return RS_UI_TOOL_SWATCH;
        }
    for (int t = RS_UI_TOOL_NONE + 1; t < RS_UI_TOOL_COUNT; t++)
        if (t != RS_UI_TOOL_SWATCH && rs_ui_rect_contains(l->tool[t], x, y)) return (rs_ui_tool)t;
    return RS_UI_TOOL_NONE;
}

// The light dial: a disc of light directions (centre = light from the camera) with a sun to drag. The
// drag moves the sun relative to where it was, geared down (RS_UI_DIAL_DRAG_PT points of drag cross
// the dial's radius): a touch anywhere on the dial does not make the light jump, and a small flick
// makes a small change. True while held.
static bool light_dial(rs_ui *ui, rs_ui_rect r, float light[2])
{
    float s = rs_ui_scale(ui);
    float cx = r.x + r.w * 0.5f, cy = r.y + r.h * 0.5f, R = r.w * 0.5f - 10 * s;
    float dx, dy;
    bool held = rs_ui_drag(ui, (int)(1000 + RS_UI_TOOL_LIGHT), r, &dx, &dy);
    if (held && (dx != 0 || dy != 0)) {
        float k = 1.0f / (RS_UI_DIAL_DRAG_PT * s);
        float x = light[0] + dx * k, y = light[1] - dy * k, d = sqrtf(x * x + y * y);
        if (d > 1) x /= d, y /= d;
        light[0] = x, light[1] = y;
    }
    rs_ui_circle(ui, cx, cy, R + 8 * s, (rs_ui_rgba){255, 255, 255, 14});
    rs_ui_ring(ui, cx, cy, R, 1.5f * s, (rs_ui_rgba){255, 255, 255, 70});
    rs_ui_line(ui, cx - R, cy, cx + R, cy, 1 * s, (rs_ui_rgba){255, 255, 255, 30});
    rs_ui_line(ui, cx, cy - R, cx, cy + R, 1 * s, (rs_ui_rgba){255, 255, 255, 30});
    float sx = cx + light[0] * R, sy = cy - light[1] * R;
    rs_ui_line(ui, cx, cy, sx, sy, 1.5f * s, (rs_ui_rgba){255, 214, 120, 120});
    float is = 20 * s;
    rs_ui_circle(ui, sx, sy, is * 0.55f, (rs_ui_rgba){0, 0, 0, 90});
    rs_ui_icon_draw(ui, RS_UI_ICON_SUN, (rs_ui_rect){sx - is * 0.5f, sy - is * 0.5f, is, is},
                    (rs_ui_rgba){255, 214, 120, 255});
    return held;
}

rs_ui_tool rs_ui_toolbar(rs_ui *ui, const rs_ui_toolbar_layout *l, rs_ui_toolbar_state *st, int *swatch)
{
    rs_ui_tool hit = RS_UI_TOOL_NONE;
    float s = rs_ui_scale(ui);
    float rad = l->target * 0.5f + PAD_PT * s;

    // Top bar: render mode segments, pipeline, then icon buttons.
    rs_ui_panel(ui, l->top, rad);
    rs_ui_rect seg = {l->tool[RS_UI_TOOL_ALBEDO].x, l->tool[RS_UI_TOOL_ALBEDO].y,
                      l->tool[RS_UI_TOOL_FULL].x + l->tool[RS_UI_TOOL_FULL].w - l->tool[RS_UI_TOOL_ALBEDO].x,
                      l->target};
    rs_ui_fill(ui, rs_ui_rect_inset(seg, 2 * s), l->target * 0.5f, (rs_ui_rgba){255, 255, 255, 16});
    static const char *const mode_label[3] = {"Albedo", "Diffuse", "Full"};
    for (int i = 0; i < 3; i++) {
        rs_ui_tool t = (rs_ui_tool)(RS_UI_TOOL_ALBEDO + i);
        if (rs_ui_text_button(ui, (int)(1000 + t), l->tool[t], mode_label[i], st->mode == i)) hit = t, st->mode = i;
    }
    if (rs_ui_text_button(ui, 1000 + RS_UI_TOOL_PIPELINE, l->tool[RS_UI_TOOL_PIPELINE],
                          st->mobile ? "Mobile" : "Reference", false))
        hit = RS_UI_TOOL_PIPELINE, st->mobile = !st->mobile;
    float sep_x = l->tool[RS_UI_TOOL_PIPELINE].x + l->tool[RS_UI_TOOL_PIPELINE].w + SEP_PT * s * 0.5f;
    float sy = l->top.y + l->top.h * 0.3f, ey = l->top.y + l->top.h * 0.7f;
    rs_ui_line(ui, sep_x, sy, sep_x, ey, 1 * s, (rs_ui_rgba){255, 255, 255, 40});
    sep_x = l->tool[RS_UI_TOOL_PIPELINE].x - SEP_PT * s * 0.5f;
    rs_ui_line(ui, sep_x, sy, sep_x, ey, 1 * s, (rs_ui_rgba){255, 255, 255, 40});
    static const rs_ui_icon top_icon[] = {RS_UI_ICON_SPLIT, RS_UI_ICON_HUD, RS_UI_ICON_SAVE,
                                          RS_UI_ICON_LOAD, RS_UI_ICON_CAMERA, RS_UI_ICON_HELP};
    const bool top_on[] = {st->split, st->hud, false, false, false, st->help};
    for (size_t i = 0; i < RS_COUNT_OF(top_icons); i++)
        if (rs_ui_button(ui, (int)(1000 + top_icons[i]), l->tool[top_icons[i]], top_icon[i], top_on[i]))
            hit = top_icons[i];

    // Left rail: paint/view, eraser, smudge/blend, mirror, region | undo, redo, clear.
    rs_ui_panel(ui, l->left, rad);
    static const rs_ui_icon left_icon[] = {RS_UI_ICON_BRUSH,  RS_UI_ICON_ERASER, RS_UI_ICON_SMUDGE, RS_UI_ICON_MIRROR,
                                           RS_UI_ICON_REGION, RS_UI_ICON_UNDO,   RS_UI_ICON_REDO,   RS_UI_ICON_TRASH};
    const bool left_on[] = {st->paint,       st->eraser, st->smudge || st->blend, st->mirror,
                            st->keep_region, false,      false,                   false};
    _Static_assert(RS_COUNT_OF(left_icon) == RS_COUNT_OF(left_tools), "left rail");
    for (size_t i = 0; i < RS_COUNT_OF(left_tools); i++) {
        rs_ui_tool t = left_tools[i];
        rs_ui_icon icon = t == RS_UI_TOOL_PAINT && !st->paint  ? RS_UI_ICON_MOVE
                          : t == RS_UI_TOOL_SMUDGE && st->blend ? RS_UI_ICON_BLEND
                                                                : left_icon[i];
        bool tap = rs_ui_button(ui, (int)(1000 + t), l->tool[t], icon, left_on[i]);
        // Undo/redo without history are drawn dimmed and do nothing.
        bool dim = (t == RS_UI_TOOL_UNDO && !st->can_undo) || (t == RS_UI_TOOL_REDO && !st->can_redo);
        if (dim) {
            rs_ui_rect r = l->tool[t];
            rs_ui_circle(ui, r.x + r.w * 0.5f, r.y + r.h * 0.5f, r.w * 0.44f, (rs_ui_rgba){22, 22, 27, 150});
        } else if (tap) {
            hit = t;
        }
    }
    float lx = l->left.x + PAD_PT * s * 2, lw = l->left.w - PAD_PT * s * 4;
    float ly = l->tool[RS_UI_TOOL_UNDO].y - SEP_PT * s * 0.5f;
    rs_ui_line(ui, lx, ly, lx + lw, ly, 1 * s, (rs_ui_rgba){255, 255, 255, 40});

    // Right rail: light dial, brush size, opacity.
    rs_ui_panel(ui, l->right, rad);
    if (light_dial(ui, l->tool[RS_UI_TOOL_LIGHT], st->light)) hit = RS_UI_TOOL_LIGHT;
    if (rs_ui_slider(ui, 1000 + RS_UI_TOOL_SIZE, l->tool[RS_UI_TOOL_SIZE], RS_UI_ICON_DOT, "Size", st->size_text,
                     &st->size))
        hit = RS_UI_TOOL_SIZE;
    if (rs_ui_slider(ui, 1000 + RS_UI_TOOL_OPACITY, l->tool[RS_UI_TOOL_OPACITY], RS_UI_ICON_DROP, "Opacity",
                     st->opacity_text, &st->opacity))
        hit = RS_UI_TOOL_OPACITY;

    // Bottom sheet: product name and swatches.
    rs_ui_panel(ui, l->bottom, rad);
    int n = RS_MIN(st->swatch_count, l->swatch_count);
    for (int i = 0; i < n; i++)
        if (rs_ui_swatch(ui, 2000 + i, l->swatch[i], st->swatch_rgb[i],
                         i == st->selected && !st->eraser && !st->smudge && !st->blend)) {
            hit = RS_UI_TOOL_SWATCH, st->selected = i, st->eraser = st->smudge = st->blend = false;
            if (swatch) *swatch = i;
        }
    // "Lipstick matte - on lips" while the brush keeps to the product's region.
    const char *product = st->eraser ? "Eraser"
                          : st->smudge ? "Smudge - drags the makeup along"
                          : st->blend  ? "Blend - softens the makeup's edges"
                          : (st->selected >= 0 && st->selected < n && st->swatch_name) ? st->swatch_name[st->selected]
                                                                                       : "";
    char name[96];
    if (!st->eraser && !st->smudge && !st->blend && st->region_name) snprintf(name, sizeof name, "%s - on %s", product, st->region_name);
    else snprintf(name, sizeof name, "%s", product);
    int ts = RS_MAX(1, (int)floorf(s * 2 + 0.25f));
    float nw = rs_ui_text_width(name, ts);
    rs_ui_text(ui, l->label.x + (l->label.w - nw) * 0.5f, l->label.y + (l->label.h - 7.0f * (float)ts) * 0.5f, ts,
               RS_UI_WHITE, name);
    return hit;
}
