// ui.c — see ui.h. The draw list, primitives, text, icons and widgets; the toolbar is in ui_toolbar.c and
// the font's glyphs in ui_font.c.
#include "ui.h"

#include "gl/gl.h"
#include "gl/shader.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define KIND_SHAPE 0.0f
#define KIND_GLYPH 1.0f
#define KIND_IMAGE 2.0f

// Font atlas: 16 x 6 cells of RS_UI_FONT_CELL_W x RS_UI_FONT_CELL_H for characters 32..127.
#define ATLAS_COLS 16
#define ATLAS_ROWS 6
#define ATLAS_W (ATLAS_COLS * RS_UI_FONT_CELL_W)
#define ATLAS_H (ATLAS_ROWS * RS_UI_FONT_CELL_H)

#define MAX_HITS 256

typedef struct vtx {
    float pos[2], local[2], half[2], shape[4], uv[2];
    uint8_t color[4];
} vtx;

// A run of vertices drawn with one image texture bound (0: none needed).
typedef struct batch {
    size_t first, count;
    GLuint image;
} batch;

struct rs_ui {
    GLuint prog, vao, vbo, font_tex;
    GLuint image_sampler;  // linear filtering for images, whatever their owner set on the texture
    GLint u_fb, u_font, u_image;
    size_t vbo_bytes;
    vtx *v;
    size_t nv;
    uint32_t cap_v;
    batch *b;
    size_t nb;
    uint32_t cap_b;
    bool oom;  // a frame that could not grow its list draws what it has

    int fb_w, fb_h;
    float scale;
    rs_ui_input in;
    float last_x, last_y;  // pointer position in the previous frame
    float drag_x, drag_y;  // where the active drag widget last saw the pointer (its deltas start at the press)
    int active;            // widget holding the pointer, 0 none
    // Interactive rects and panels: this frame's (being built) and last frame's (for rs_ui_captures).
    rs_ui_rect hits[2][MAX_HITS];
    int nhits[2];
};

bool rs_ui_rect_contains(rs_ui_rect r, float x, float y)
{
    return x >= r.x && y >= r.y && x < r.x + r.w && y < r.y + r.h;
}

rs_ui_rect rs_ui_rect_inset(rs_ui_rect r, float d)
{
    return (rs_ui_rect){r.x + d, r.y + d, r.w - 2 * d, r.h - 2 * d};
}

static rs_result make_font_texture(GLuint *out)
{
    static uint8_t px[ATLAS_W * ATLAS_H];
    memset(px, 0, sizeof px);
    for (int ch = 32; ch < 127; ch++) {
        uint8_t rows[9];
        rs_ui_font_glyph(ch, rows);
        int cx = (ch - 32) % ATLAS_COLS * RS_UI_FONT_CELL_W, cy = (ch - 32) / ATLAS_COLS * RS_UI_FONT_CELL_H;
        for (int r = 0; r < 9; r++)
            for (int c = 0; c < 5; c++)
                if (rows[r] & (0x10 >> c)) px[(cy + r) * ATLAS_W + cx + c] = 255;
    }
    glGenTextures(1, out);
    glBindTexture(GL_TEXTURE_2D, *out);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_R8, ATLAS_W, ATLAS_H, 0, GL_RED, GL_UNSIGNED_BYTE, px);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    // Nearest: text is drawn at integer scales on whole pixels, so it stays crisp.
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return RS_OK;
}

rs_result rs_ui_create(rs_ui **out, rs_error *err)
{
    rs_ui *ui = calloc(1, sizeof *ui);
    if (!ui) return rs_fail(err, RS_ERR_NOMEM, "ui: out of memory");
    rs_result r = rs_shader_program("ui.vert.glsl", "ui.frag.glsl", NULL, &ui->prog, err);
    if (r != RS_OK) {
        free(ui);
        return r;
    }
    ui->u_fb = glGetUniformLocation(ui->prog, "u_fb");
    ui->u_font = glGetUniformLocation(ui->prog, "u_font");
    ui->u_image = glGetUniformLocation(ui->prog, "u_image");
    make_font_texture(&ui->font_tex);
    // Pictures rendered at a lower resolution (adaptive quality) are scaled up smoothly.
    glGenSamplers(1, &ui->image_sampler);
    glSamplerParameteri(ui->image_sampler, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glSamplerParameteri(ui->image_sampler, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glSamplerParameteri(ui->image_sampler, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glSamplerParameteri(ui->image_sampler, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glGenVertexArrays(1, &ui->vao);
    glGenBuffers(1, &ui->vbo);
    glBindVertexArray(ui->vao);
    glBindBuffer(GL_ARRAY_BUFFER, ui->vbo);
    const GLsizei st = sizeof(vtx);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, st, (void *)offsetof(vtx, pos));
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 2, GL_FLOAT, GL_FALSE, st, (void *)offsetof(vtx, local));
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 2, GL_FLOAT, GL_FALSE, st, (void *)offsetof(vtx, half));
    glEnableVertexAttribArray(3);
    glVertexAttribPointer(3, 4, GL_FLOAT, GL_FALSE, st, (void *)offsetof(vtx, shape));
    glEnableVertexAttribArray(4);
    glVertexAttribPointer(4, 2, GL_FLOAT, GL_FALSE, st, (void *)offsetof(vtx, uv));
    glEnableVertexAttribArray(5);
    glVertexAttribPointer(5, 4, GL_UNSIGNED_BYTE, GL_TRUE, st, (void *)offsetof(vtx, color));
    glBindVertexArray(0);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    r = rs_gl_check("ui: create", err);
    if (r != RS_OK) {
        rs_ui_destroy(ui);
        return r;
    }
    ui->scale = 1;
    *out = ui;
    return RS_OK;
}

void rs_ui_destroy(rs_ui *ui)
{
    if (!ui) return;
    glDeleteProgram(ui->prog);
    glDeleteVertexArrays(1, &ui->vao);
    glDeleteBuffers(1, &ui->vbo);
    glDeleteTextures(1, &ui->font_tex);
    glDeleteSamplers(1, &ui->image_sampler);
    free(ui->v);
    free(ui->b);
    free(ui);
}

void rs_ui_begin(rs_ui *ui, int fb_w, int fb_h, float scale, const rs_ui_input *in)
{
    ui->fb_w = fb_w, ui->fb_h = fb_h;
    ui->scale = scale > 0 ? scale : 1;
    ui->last_x = ui->in.x, ui->last_y = ui->in.y;
    ui->in = *in;
    ui->nv = ui->nb = 0;
    ui->oom = false;
    ui->nhits[0] = 0;
}

float rs_ui_scale(const rs_ui *ui) { return ui->scale; }

void rs_ui_end_input(rs_ui *ui)
{
    // This frame's hit areas become the ones rs_ui_captures answers from.
    memcpy(ui->hits[1], ui->hits[0], sizeof ui->hits[0]);
    ui->nhits[1] = ui->nhits[0];
    // A widget only keeps the pointer while the button is held.
    if (!ui->in.down) ui->active = 0;
}

void rs_ui_end(rs_ui *ui)
{
    rs_ui_end_input(ui);
    if (ui->nv == 0) return;
    size_t bytes = ui->nv * sizeof(vtx);
    glBindBuffer(GL_ARRAY_BUFFER, ui->vbo);
    if (bytes > ui->vbo_bytes) {
        glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)bytes, NULL, GL_STREAM_DRAW);
        ui->vbo_bytes = bytes;
    }
    glBufferSubData(GL_ARRAY_BUFFER, 0, (GLsizeiptr)bytes, ui->v);
    glViewport(0, 0, ui->fb_w, ui->fb_h);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glDisable(GL_SCISSOR_TEST);
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_ONE, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    glUseProgram(ui->prog);
    glUniform2f(ui->u_fb, (float)ui->fb_w, (float)ui->fb_h);
    glUniform1i(ui->u_font, 0);
    glUniform1i(ui->u_image, 1);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, ui->font_tex);
    glBindSampler(1, ui->image_sampler);
    glBindVertexArray(ui->vao);
    for (size_t i = 0; i < ui->nb; i++) {
        glActiveTexture(GL_TEXTURE1);
        glBindTexture(GL_TEXTURE_2D, ui->b[i].image);
        glDrawArrays(GL_TRIANGLES, (GLint)ui->b[i].first, (GLsizei)ui->b[i].count);
    }
    glBindVertexArray(0);
    glBindSampler(1, 0);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, 0);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, 0);
    glDisable(GL_BLEND);
    glUseProgram(0);
}

bool rs_ui_captures(const rs_ui *ui, float x, float y)
{
    if (ui->active) return true;
    for (int i = 0; i < ui->nhits[1]; i++)
        if (rs_ui_rect_contains(ui->hits[1][i], x, y)) return true;
    return false;
}


void rs_ui_pointer(const rs_ui *ui, float *x, float *y)
{
    *x = ui->in.x, *y = ui->in.y;
}

static void add_hit(rs_ui *ui, rs_ui_rect r)
{
    if (ui->nhits[0] < MAX_HITS) ui->hits[0][ui->nhits[0]++] = r;
}

// --- the draw list ---------------------------------------------------------------------------------

// Appends 6 vertices to the batch for `image` (0: any batch will do) and returns them.
static vtx *alloc6(rs_ui *ui, GLuint image)
{
    if (ui->oom) return NULL;
    if (!rs_array_grow((void **)&ui->v, &ui->cap_v, (uint32_t)ui->nv + 6, sizeof(vtx)) ||
        !rs_array_grow((void **)&ui->b, &ui->cap_b, (uint32_t)ui->nb + 1, sizeof(batch))) {
        ui->oom = true;
        return NULL;
    }
    batch *last = ui->nb ? &ui->b[ui->nb - 1] : NULL;
    if (!last || (image && last->image && last->image != image)) {
        ui->b[ui->nb++] = (batch){.first = ui->nv, .count = 0, .image = image};
        last = &ui->b[ui->nb - 1];
    }
    if (image) last->image = image;
    last->count += 6;
    vtx *v = ui->v + ui->nv;
    ui->nv += 6;
    return v;
}

// A quad centred at (cx, cy) along unit axis (ux, uy), half extents (hx, hy) plus `pad` pixels of room
// for the anti-aliased edge; uv spans {u0, v0, u1, v1} from the quad's -x,-y corner to its +x,+y corner.
static void quad(rs_ui *ui, float cx, float cy, float ux, float uy, float hx, float hy, float pad,
                 const float shape[4], const float uv[4], rs_ui_rgba c, GLuint image)
{
    vtx *v = alloc6(ui, image);
    if (!v) return;
    float ex = hx + pad, ey = hy + pad;
    // Screen axes of the shape: u along x, w = u rotated by +90 degrees (y down).
    float wx = -uy, wy = ux;
    static const float corner[6][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, -1}, {1, 1}, {-1, 1}};
    for (int i = 0; i < 6; i++) {
        float sx = corner[i][0], sy = corner[i][1];
        float lx = sx * ex, ly = sy * ey;
        v[i] = (vtx){.pos = {cx + ux * lx + wx * ly, cy + uy * lx + wy * ly},
                     .local = {lx, ly},
                     .half = {hx, hy},
                     .shape = {shape[0], shape[1], shape[2], shape[3]},
                     .uv = {sx < 0 ? uv[0] : uv[2], sy < 0 ? uv[1] : uv[3]},
                     .color = {c.r, c.g, c.b, c.a}};
    }
}

static const float no_uv[4] = {0, 0, 0, 0};

static void box(rs_ui *ui, rs_ui_rect r, float radius, float stroke, float feather, rs_ui_rgba c)
{
    if (r.w <= 0 || r.h <= 0 || c.a == 0) return;
    float hx = r.w * 0.5f, hy = r.h * 0.5f;
    radius = RS_CLAMP(radius, 0.0f, RS_MIN(hx, hy));
    float shape[4] = {radius, stroke, feather, KIND_SHAPE};
    quad(ui, r.x + hx, r.y + hy, 1, 0, hx, hy, feather * 0.5f + 1, shape, no_uv, c, 0);
}

void rs_ui_fill(rs_ui *ui, rs_ui_rect r, float radius, rs_ui_rgba c) { box(ui, r, radius, 0, 1, c); }

void rs_ui_stroke(rs_ui *ui, rs_ui_rect r, float radius, float width, rs_ui_rgba c)
{
    box(ui, r, radius, width, 1, c);
}

void rs_ui_shadow(rs_ui *ui, rs_ui_rect r, float radius, float blur, rs_ui_rgba c) { box(ui, r, radius, 0, blur, c); }

void rs_ui_circle(rs_ui *ui, float cx, float cy, float r, rs_ui_rgba c)
{
    box(ui, (rs_ui_rect){cx - r, cy - r, 2 * r, 2 * r}, r, 0, 1, c);
}

void rs_ui_ring(rs_ui *ui, float cx, float cy, float r, float width, rs_ui_rgba c)
{
    // r is the ring's centre line; the stroke band lies inside the outline, so grow by half the width.
    float o = r + width * 0.5f;
    box(ui, (rs_ui_rect){cx - o, cy - o, 2 * o, 2 * o}, o, width, 1, c);
}

void rs_ui_line(rs_ui *ui, float x0, float y0, float x1, float y1, float width, rs_ui_rgba c)
{
    float dx = x1 - x0, dy = y1 - y0, len = sqrtf(dx * dx + dy * dy);
    float ux = 1, uy = 0;
    if (len > 1e-4f) ux = dx / len, uy = dy / len;
    float hw = width * 0.5f;
    float shape[4] = {hw, 0, 1, KIND_SHAPE};
    quad(ui, (x0 + x1) * 0.5f, (y0 + y1) * 0.5f, ux, uy, len * 0.5f + hw, hw, 1.5f, shape, no_uv, c, 0);
}

void rs_ui_arc(rs_ui *ui, float cx, float cy, float r, float a0, float a1, float width, rs_ui_rgba c)
{
    int n = (int)RS_CLAMP(fabsf(a1 - a0) * r / (3.0f * ui->scale), 4.0f, 48.0f);
    float px = cx + r * cosf(a0), py = cy - r * sinf(a0);
    for (int i = 1; i <= n; i++) {
        float a = a0 + (a1 - a0) * (float)i / (float)n;
        float x = cx + r * cosf(a), y = cy - r * sinf(a);
        rs_ui_line(ui, px, py, x, y, width, c);
        px = x, py = y;
    }
}

void rs_ui_image(rs_ui *ui, GLuint texture, rs_ui_rect r, const float uv[4])
{
    if (!texture || r.w <= 0 || r.h <= 0) return;
    float shape[4] = {0, 0, 1, KIND_IMAGE};
    quad(ui, r.x + r.w * 0.5f, r.y + r.h * 0.5f, 1, 0, r.w * 0.5f, r.h * 0.5f, 0, shape, uv,
         (rs_ui_rgba){255, 255, 255, 255}, texture);
}

void rs_ui_panel(rs_ui *ui, rs_ui_rect r, float radius)
{
    float s = ui->scale;
    rs_ui_shadow(ui, (rs_ui_rect){r.x, r.y + 3 * s, r.w, r.h}, radius, 18 * s, (rs_ui_rgba){0, 0, 0, 90});
    rs_ui_fill(ui, r, radius, RS_UI_PANEL);
    rs_ui_stroke(ui, r, radius, 1, (rs_ui_rgba){255, 255, 255, 22});
    add_hit(ui, r);
}

// --- text ------------------------------------------------------------------------------------------

float rs_ui_text_width(const char *s, int scale)
{
    size_t n = strlen(s);
    // The last glyph's spacing column is not part of the ink.
    return n ? (float)((int)n * RS_UI_FONT_CELL_W - 1) * (float)scale : 0.0f;
}

float rs_ui_text(rs_ui *ui, float x, float y, int scale, rs_ui_rgba c, const char *s)
{
    if (scale < 1) scale = 1;
    x = floorf(x + 0.5f), y = floorf(y + 0.5f);
    float cw = (float)(RS_UI_FONT_CELL_W * scale), ch = (float)(RS_UI_FONT_CELL_H * scale);
    float shape[4] = {0, 0, 1, KIND_GLYPH};
    float pen = x;
    for (const unsigned char *p = (const unsigned char *)s; *p; p++, pen += cw) {
        int g = (*p >= 32 && *p < 127) ? *p : '?';
        if (g == ' ') continue;
        float u0 = (float)((g - 32) % ATLAS_COLS * RS_UI_FONT_CELL_W) / ATLAS_W;
        float v0 = (float)((g - 32) / ATLAS_COLS * RS_UI_FONT_CELL_H) / ATLAS_H;
        float uv[4] = {u0, v0, u0 + (float)RS_UI_FONT_CELL_W / ATLAS_W, v0 + (float)RS_UI_FONT_CELL_H / ATLAS_H};
        quad(ui, pen + cw * 0.5f, y + ch * 0.5f, 1, 0, cw * 0.5f, ch * 0.5f, 0, shape, uv, c, 0);
    }
    return rs_ui_text_width(s, scale);
}

// --- icons: drawn on a 24 x 24 design grid scaled into the rect ---------------------------------------

typedef struct pen {
    rs_ui *ui;
    float x, y, k, w;  // origin, pixels per grid unit, stroke width in pixels
    rs_ui_rgba c;
} pen;

static void L(const pen *p, float x0, float y0, float x1, float y1)
{
    rs_ui_line(p->ui, p->x + x0 * p->k, p->y + y0 * p->k, p->x + x1 * p->k, p->y + y1 * p->k, p->w, p->c);
}

static void A(const pen *p, float cx, float cy, float r, float a0_deg, float a1_deg)
{
    const float d = 3.14159265f / 180.0f;
    rs_ui_arc(p->ui, p->x + cx * p->k, p->y + cy * p->k, r * p->k, a0_deg * d, a1_deg * d, p->w, p->c);
}

static void R(const pen *p, float x, float y, float w, float h, float radius)
{
    rs_ui_stroke(p->ui, (rs_ui_rect){p->x + x * p->k, p->y + y * p->k, w * p->k, h * p->k}, radius * p->k, p->w,
                 p->c);
}

static void D(const pen *p, float cx, float cy, float r)
{
    rs_ui_circle(p->ui, p->x + cx * p->k, p->y + cy * p->k, r * p->k, p->c);
}

void rs_ui_icon_draw(rs_ui *ui, rs_ui_icon icon, rs_ui_rect r, rs_ui_rgba c)
{
    float side = RS_MIN(r.w, r.h);
    pen p = {ui, r.x + (r.w - side) * 0.5f, r.y + (r.h - side) * 0.5f, side / 24.0f, RS_MAX(1.5f, side / 12.0f), c};
    switch (icon) {
    case RS_UI_ICON_BRUSH:  // a slanted brush: handle, ferrule, soft tip
        L(&p, 19, 5, 12, 12);
        L(&p, 12, 12, 10, 14);
        D(&p, 7.5f, 16.5f, 3.4f);
        L(&p, 5, 19, 4, 20.5f);
        break;
    case RS_UI_ICON_MOVE:  // four arrows: navigate
        L(&p, 12, 3, 12, 21);
        L(&p, 3, 12, 21, 12);
        L(&p, 9, 6, 12, 3), L(&p, 15, 6, 12, 3);
        L(&p, 9, 18, 12, 21), L(&p, 15, 18, 12, 21);
        L(&p, 6, 9, 3, 12), L(&p, 6, 15, 3, 12);
        L(&p, 18, 9, 21, 12), L(&p, 18, 15, 21, 12);
        break;
    case RS_UI_ICON_ERASER:  // a tilted block and the line it leaves clean
        L(&p, 4, 14, 13, 5), L(&p, 13, 5, 19, 11), L(&p, 19, 11, 10, 20), L(&p, 10, 20, 4, 14);
        L(&p, 8.5f, 9.5f, 14.5f, 15.5f);
        L(&p, 10, 20, 20, 20);
        break;
    case RS_UI_ICON_UNDO:
        A(&p, 12.5f, 13, 6.5f, 160, -110);
        L(&p, 6.2f, 10.5f, 4, 6), L(&p, 6.2f, 10.5f, 10.8f, 9.3f);
        break;
    case RS_UI_ICON_REDO:
        A(&p, 11.5f, 13, 6.5f, 20, 290);
        L(&p, 17.8f, 10.5f, 20, 6), L(&p, 17.8f, 10.5f, 13.2f, 9.3f);
        break;
    case RS_UI_ICON_MIRROR:  // two triangles facing a dashed mid-line
        L(&p, 12, 3, 12, 6), L(&p, 12, 9, 12, 12), L(&p, 12, 15, 12, 18), L(&p, 12, 21, 12, 21.5f);
        L(&p, 9, 6, 9, 18), L(&p, 9, 18, 3, 18), L(&p, 3, 18, 9, 6);
        L(&p, 15, 6, 15, 18), L(&p, 15, 18, 21, 18), L(&p, 21, 18, 15, 6);
        break;
    case RS_UI_ICON_TRASH:
        L(&p, 4, 6, 20, 6);
        L(&p, 9, 6, 9.5f, 3.5f), L(&p, 9.5f, 3.5f, 14.5f, 3.5f), L(&p, 14.5f, 3.5f, 15, 6);
        L(&p, 6, 6, 7, 20.5f), L(&p, 7, 20.5f, 17, 20.5f), L(&p, 17, 20.5f, 18, 6);
        L(&p, 10, 10, 10, 17), L(&p, 14, 10, 14, 17);
        break;
    case RS_UI_ICON_SPLIT:  // a frame cut in two, left half shaded
        R(&p, 3, 4, 18, 16, 3);
        rs_ui_fill(ui, (rs_ui_rect){p.x + 3 * p.k, p.y + 4 * p.k, 9 * p.k, 16 * p.k}, 3 * p.k,
                   (rs_ui_rgba){c.r, c.g, c.b, (uint8_t)(c.a / 3)});
        L(&p, 12, 2, 12, 22);
        break;
    case RS_UI_ICON_SAVE:  // arrow down into a tray
        L(&p, 12, 3, 12, 14), L(&p, 7.5f, 9.5f, 12, 14), L(&p, 16.5f, 9.5f, 12, 14);
        L(&p, 4, 14, 4, 20), L(&p, 4, 20, 20, 20), L(&p, 20, 20, 20, 14);
        break;
    case RS_UI_ICON_LOAD:  // folder
        L(&p, 3, 7, 3, 19), L(&p, 3, 19, 21, 19), L(&p, 21, 19, 21, 9), L(&p, 21, 9, 11, 9);
        L(&p, 11, 9, 9, 6), L(&p, 9, 6, 4, 6), L(&p, 4, 6, 3, 7);
        break;
    case RS_UI_ICON_CAMERA:
        R(&p, 3, 7, 18, 13, 3);
        L(&p, 8, 7, 9.5f, 4.5f), L(&p, 9.5f, 4.5f, 14.5f, 4.5f), L(&p, 14.5f, 4.5f, 16, 7);
        A(&p, 12, 13.5f, 3.6f, 0, 360);
        break;
    case RS_UI_ICON_HELP:
        A(&p, 12, 12, 9, 0, 360);
        A(&p, 12, 9.5f, 3, 160, -60);
        L(&p, 13.5f, 12.1f, 12, 13.5f), L(&p, 12, 13.5f, 12, 14.5f);
        D(&p, 12, 17.5f, 1.3f);
        break;
    case RS_UI_ICON_HUD:  // bar chart
        L(&p, 5, 20, 5, 13), L(&p, 10, 20, 10, 6), L(&p, 15, 20, 15, 10), L(&p, 20, 20, 20, 4);
        break;
    case RS_UI_ICON_SUN:
        D(&p, 12, 12, 4.2f);
        for (int i = 0; i < 8; i++) {
            float a = (float)i * 3.14159265f / 4.0f, ca = cosf(a), sa = sinf(a);
            L(&p, 12 + 7 * ca, 12 + 7 * sa, 12 + 9.5f * ca, 12 + 9.5f * sa);
        }
        break;
    case RS_UI_ICON_DOT:  // brush size: a small and a big dot
        D(&p, 6.5f, 15, 2.2f);
        D(&p, 15, 12, 5.5f);
        break;
    case RS_UI_ICON_DROP:  // opacity: a drop
        A(&p, 12, 14.5f, 5.5f, 200, 340);
        L(&p, 6.9f, 12.6f, 12, 3.5f), L(&p, 17.1f, 12.6f, 12, 3.5f);
        break;
    case RS_UI_ICON_REGION:  // a dashed outline (the region) holding a dot of paint
        for (int i = 0; i < 8; i++) A(&p, 12, 12, 8.5f, (float)i * 45.0f + 8.0f, (float)i * 45.0f + 30.0f);
        D(&p, 12, 12, 4.0f);
        break;
    case RS_UI_ICON_SMUDGE:  // a fingertip pressed down at the upper right, its smear fading to the lower left
        A(&p, 16.5f, 7.5f, 3.8f, 0, 360);
        L(&p, 13.8f, 10.2f, 4, 20), L(&p, 16.5f, 11.3f, 9, 20.5f), L(&p, 12.7f, 7.5f, 5, 13.5f);
        break;
    case RS_UI_ICON_BLEND:  // a round brush head over a line that turns from solid to dotted
        D(&p, 12, 8, 4.5f);
        L(&p, 12, 12.5f, 12, 14.5f);
        L(&p, 3, 19, 10, 19), D(&p, 13, 19, 1.1f), D(&p, 16.5f, 19, 0.8f), D(&p, 20, 19, 0.5f);
        break;
    case RS_UI_ICON_CLOSE:
        L(&p, 6, 6, 18, 18), L(&p, 18, 6, 6, 18);
        break;
    case RS_UI_ICON_CHEVRONS:
        L(&p, 9, 7, 4, 12), L(&p, 4, 12, 9, 17);
        L(&p, 15, 7, 20, 12), L(&p, 20, 12, 15, 17);
        break;
    case RS_UI_ICON_NONE:
    case RS_UI_ICON_COUNT:
        break;
    }
}

// --- widgets ---------------------------------------------------------------------------------------

// The shared press/release logic: returns true on a tap (pressed and released on the widget).
static bool press_logic(rs_ui *ui, int id, rs_ui_rect r, bool *hot)
{
    add_hit(ui, r);
    bool inside = rs_ui_rect_contains(r, ui->in.x, ui->in.y);
    *hot = inside && (ui->active == 0 || ui->active == id) && ui->in.inside;
    if (ui->in.pressed && inside && ui->active == 0) ui->active = id;
    if (ui->active == id && ui->in.released) {
        ui->active = 0;
        return inside;
    }
    return false;
}

bool rs_ui_button(rs_ui *ui, int id, rs_ui_rect r, rs_ui_icon icon, bool on)
{
    bool hot;
    bool tap = press_logic(ui, id, r, &hot);
    float cx = r.x + r.w * 0.5f, cy = r.y + r.h * 0.5f, rad = RS_MIN(r.w, r.h) * 0.44f;
    if (on) rs_ui_circle(ui, cx, cy, rad, RS_UI_ACCENT);
    else if (ui->active == id) rs_ui_circle(ui, cx, cy, rad, (rs_ui_rgba){255, 255, 255, 50});
    else if (hot) rs_ui_circle(ui, cx, cy, rad, (rs_ui_rgba){255, 255, 255, 26});
    float is = rad * 1.05f;
    rs_ui_icon_draw(ui, icon, (rs_ui_rect){cx - is * 0.5f * 1.0f, cy - is * 0.5f, is, is}, RS_UI_WHITE);
    return tap;
}

bool rs_ui_text_button(rs_ui *ui, int id, rs_ui_rect r, const char *label, bool on)
{
    bool hot;
    bool tap = press_logic(ui, id, r, &hot);
    float rad = r.h * 0.5f;
    rs_ui_rect in = rs_ui_rect_inset(r, 4 * ui->scale);
    if (on) rs_ui_fill(ui, in, rad, RS_UI_ACCENT);
    else if (ui->active == id) rs_ui_fill(ui, in, rad, (rs_ui_rgba){255, 255, 255, 50});
    else if (hot) rs_ui_fill(ui, in, rad, (rs_ui_rgba){255, 255, 255, 26});
    int ts = RS_MAX(1, (int)floorf(ui->scale * 2 + 0.25f));
    while (ts > 1 && rs_ui_text_width(label, ts) > in.w - 8 * ui->scale) ts--;
    float tw = rs_ui_text_width(label, ts), th = 7.0f * (float)ts;
    rs_ui_text(ui, r.x + (r.w - tw) * 0.5f, r.y + (r.h - th) * 0.5f, ts, on ? RS_UI_WHITE : (rs_ui_rgba){225, 225, 230, 255},
               label);
    return tap;
}

bool rs_ui_swatch(rs_ui *ui, int id, rs_ui_rect r, const uint8_t rgb[3], bool selected)
{
    bool hot;
    bool tap = press_logic(ui, id, r, &hot);
    float s = ui->scale;
    float cx = r.x + r.w * 0.5f, cy = r.y + r.h * 0.5f, rad = RS_MIN(r.w, r.h) * 0.5f - 5 * s;
    if (selected) rad -= 1.5f * s;
    if (hot && !selected) rad += 1.5f * s;
    rs_ui_circle(ui, cx, cy + 1.5f * s, rad + 1.5f * s, (rs_ui_rgba){0, 0, 0, 70});
    rs_ui_circle(ui, cx, cy, rad, (rs_ui_rgba){rgb[0], rgb[1], rgb[2], 255});
    // A faint rim keeps dark shades visible on the dark sheet, and a soft highlight reads as a pan of product.
    rs_ui_ring(ui, cx, cy, rad - 0.5f * s, 1.0f * s, (rs_ui_rgba){255, 255, 255, 40});
    rs_ui_circle(ui, cx - rad * 0.35f, cy - rad * 0.4f, rad * 0.28f, (rs_ui_rgba){255, 255, 255, 40});
    if (selected) rs_ui_ring(ui, cx, cy, rad + 4.0f * s, 2.5f * s, RS_UI_WHITE);
    return tap;
}

bool rs_ui_slider(rs_ui *ui, int id, rs_ui_rect r, rs_ui_icon icon, const char *label, const char *value_text,
                  float *value)
{
    bool hot;
    press_logic(ui, id, r, &hot);
    float s = ui->scale;
    bool vertical = r.h > r.w;
    float icon_sz = RS_MIN(r.w, r.h) * 0.5f;
    if (vertical) icon_sz = RS_MIN(icon_sz, 24 * s);
    // Text: the name small and dim, the value at the toolbar's text size, centred above a vertical track
    // (after a horizontal one).
    int ts = RS_MAX(1, (int)floorf(s * 2 + 0.25f)), ts_small = RS_MAX(1, (int)floorf(s + 0.25f));
    float text_h = (label ? 11.0f * (float)ts_small + 3 * s : 0) + (value_text ? 9.0f * (float)ts : 0);
    if (vertical && (label || value_text)) {
        float ty = r.y + 2 * s;
        if (label) {
            float w = rs_ui_text_width(label, ts_small);
            rs_ui_text(ui, r.x + (r.w - w) * 0.5f, ty, ts_small, RS_UI_DIM, label);
            ty += 11.0f * (float)ts_small + 3 * s;
        }
        if (value_text) {
            float w = rs_ui_text_width(value_text, ts);
            rs_ui_text(ui, r.x + (r.w - w) * 0.5f, ty, ts, RS_UI_WHITE, value_text);
        }
    }
    // Track from a (value 0) to b (value 1), leaving room for the icon at the low end (a vertical slider
    // with a name needs no icon: the track takes the room).
    float ax, ay, bx, by;
    float knob = 11 * s;
    if (vertical) {
        ax = bx = r.x + r.w * 0.5f;
        ay = r.y + r.h - knob - 4 * s - (label ? 0 : icon_sz * 2.0f - 4 * s);
        by = r.y + knob + 4 * s + (text_h > 0 ? text_h + 6 * s : 0);
        if (!label)
            rs_ui_icon_draw(ui, icon, (rs_ui_rect){ax - icon_sz * 0.5f, r.y + r.h - icon_sz * 1.5f, icon_sz, icon_sz},
                            RS_UI_DIM);
    } else {
        ay = by = r.y + r.h * 0.5f;
        ax = r.x + icon_sz * 2.0f + knob;
        float text_w = 0;
        if (label) text_w += rs_ui_text_width(label, ts_small) + 8 * s;
        if (value_text) text_w += rs_ui_text_width(value_text, ts) + 8 * s;
        bx = r.x + r.w - knob - 4 * s - text_w;
        rs_ui_icon_draw(ui, icon, (rs_ui_rect){r.x + icon_sz * 0.5f, ay - icon_sz * 0.5f, icon_sz, icon_sz}, RS_UI_DIM);
        float tx = bx + knob + 8 * s;
        if (label) tx += rs_ui_text(ui, tx, ay - 4.5f * (float)ts_small, ts_small, RS_UI_DIM, label) + 8 * s;
        if (value_text) rs_ui_text(ui, tx, ay - 4.5f * (float)ts, ts, RS_UI_WHITE, value_text);
    }
    float old = *value;
    if (ui->active == id) {
        float t = vertical ? (ui->in.y - ay) / (by - ay) : (ui->in.x - ax) / (bx - ax);
        *value = RS_CLAMP(t, 0.0f, 1.0f);
    }
    float v = RS_CLAMP(*value, 0.0f, 1.0f);
    float kx = ax + (bx - ax) * v, ky = ay + (by - ay) * v;
    rs_ui_line(ui, ax, ay, bx, by, 5 * s, (rs_ui_rgba){255, 255, 255, 45});
    rs_ui_line(ui, ax, ay, kx, ky, 5 * s, RS_UI_ACCENT);
    rs_ui_circle(ui, kx, ky + 1.5f * s, knob + 1.5f * s, (rs_ui_rgba){0, 0, 0, 80});
    rs_ui_circle(ui, kx, ky, ui->active == id ? knob * 1.15f : knob, RS_UI_WHITE);
    return *value != old;
}

bool rs_ui_area(rs_ui *ui, int id, rs_ui_rect r)
{
    bool hot;
    return press_logic(ui, id, r, &hot);
}

bool rs_ui_hot(const rs_ui *ui, int id, rs_ui_rect r)
{
    return rs_ui_rect_contains(r, ui->in.x, ui->in.y) && ui->in.inside && (ui->active == 0 || ui->active == id);
}

bool rs_ui_drag(rs_ui *ui, int id, rs_ui_rect r, float *dx, float *dy)
{
    bool hot, was_active = ui->active == id;
    press_logic(ui, id, r, &hot);
    *dx = *dy = 0;
    if (ui->active != id) return false;
    // Deltas count from the press, not from where the pointer hovered the frame before: a new touch (or a
    // click after the mouse moved) arrives somewhere else, and that jump once threw the divider 200+ px.
    if (!was_active) ui->drag_x = ui->in.x, ui->drag_y = ui->in.y;
    *dx = ui->in.x - ui->drag_x, *dy = ui->in.y - ui->drag_y;
    ui->drag_x = ui->in.x, ui->drag_y = ui->in.y;
    return true;
}

// --- GPU helpers ---------------------------------------------------------------------------------------

rs_result rs_ui_texture_copy(rs_ui_texture *dst, GLuint src, int w, int h, rs_error *err)
{
    if (!src || w <= 0 || h <= 0) return rs_fail(err, RS_ERR_ARG, "ui: texture copy of an empty source");
    if (!dst->tex || dst->width != w || dst->height != h) {
        rs_ui_texture_free(dst);
        glGenTextures(1, &dst->tex);
        glBindTexture(GL_TEXTURE_2D, dst->tex);
        glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA8, w, h);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        glBindTexture(GL_TEXTURE_2D, 0);
        glGenFramebuffers(1, &dst->fbo);
        dst->width = w, dst->height = h;
    }
    // Attach the source to our FBO and copy from it into dst.
    GLint prev_read = 0;
    glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &prev_read);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, dst->fbo);
    glFramebufferTexture2D(GL_READ_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, src, 0);
    rs_result r = RS_OK;
    if (glCheckFramebufferStatus(GL_READ_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        r = rs_fail(err, RS_ERR_GL, "ui: cannot read the source texture (incomplete framebuffer)");
    } else {
        glBindTexture(GL_TEXTURE_2D, dst->tex);
        glCopyTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, 0, 0, w, h);
        glBindTexture(GL_TEXTURE_2D, 0);
    }
    glFramebufferTexture2D(GL_READ_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, 0, 0);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, (GLuint)prev_read);
    if (r == RS_OK) r = rs_gl_check("ui: texture copy", err);
    return r;
}

rs_result rs_ui_texture_upload(rs_ui_texture *dst, const rs_image *img, rs_error *err)
{
    if (!img->pixels || img->width <= 0 || img->height <= 0 || (img->channels != 3 && img->channels != 4))
        return rs_fail(err, RS_ERR_ARG, "ui: texture upload of an empty or odd image");
    // GLES 3 uploads into RGBA8 storage only from RGBA data: widen RGB first.
    const uint8_t *px = img->pixels;
    uint8_t *rgba = NULL;
    if (img->channels == 3) {
        rgba = rs_alloc_array((size_t)img->width * (size_t)img->height, 4);
        if (!rgba) return rs_fail(err, RS_ERR_NOMEM, "ui: texture upload: out of memory");
        for (size_t i = 0; i < (size_t)img->width * (size_t)img->height; i++) {
            memcpy(rgba + i * 4, img->pixels + i * 3, 3);
            rgba[i * 4 + 3] = 255;
        }
        px = rgba;
    }
    if (!dst->tex || dst->width != img->width || dst->height != img->height) {
        rs_ui_texture_free(dst);
        glGenTextures(1, &dst->tex);
        glBindTexture(GL_TEXTURE_2D, dst->tex);
        glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA8, img->width, img->height);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        dst->width = img->width, dst->height = img->height;
    }
    glBindTexture(GL_TEXTURE_2D, dst->tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, img->width, img->height, GL_RGBA, GL_UNSIGNED_BYTE, px);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glBindTexture(GL_TEXTURE_2D, 0);
    free(rgba);
    return rs_gl_check("ui: texture upload", err);
}

void rs_ui_texture_free(rs_ui_texture *t)
{
    if (t->tex) glDeleteTextures(1, &t->tex);
    if (t->fbo) glDeleteFramebuffers(1, &t->fbo);
    *t = (rs_ui_texture){0};
}

rs_result rs_ui_read_pixels(int w, int h, rs_image *out, rs_error *err)
{
    rs_image img = {0};
    rs_result r = rs_image_create(w, h, 4, &img, err);
    if (r != RS_OK) return r;
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, img.pixels);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    r = rs_gl_check("ui: read pixels", err);
    if (r != RS_OK) {
        rs_image_free(&img);
        return r;
    }
    // GL rows are bottom-first; images are top-first. The window's alpha is not meaningful: make it opaque.
    size_t row = (size_t)w * 4;
    for (int y = 0; y < h / 2; y++) {
        uint8_t *a = img.pixels + (size_t)y * row, *b = img.pixels + (size_t)(h - 1 - y) * row;
        for (size_t i = 0; i < row; i++) {
            uint8_t t = a[i];
            a[i] = b[i], b[i] = t;
        }
    }
    for (size_t i = 3; i < row * (size_t)h; i += 4) img.pixels[i] = 255;
    *out = img;
    return RS_OK;
}
