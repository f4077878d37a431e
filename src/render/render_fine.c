// render_fine.c — the makeup's fine layer (makeup.c, "Two resolutions"): narrow-brush stamps evaluated per
// pixel in stage 5 at the surface point each pixel sees, so a liner's edge is as sharp as the picture, not
// as soft as the splats. Uploads the stamps and their products into an RGBA32F texture and a uniform
// model-space grid over them (cell >= the typical stamp's diameter; a wider one is listed in every cell it
// reaches) into an R32UI texture: per cell (start, count), then the stamp lists in log order. Both are read with
// texelFetch only and never attached to a framebuffer (WebGL 2 rejects feedback loops).
#include "render/render_stages.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define FINE_TEX_WIDTH 1024        // texels per row of both textures (shaders_es/makeup_fine.glsl)
#define FINE_DIM_MAX 32            // grid cells per axis
#define FINE_STAMPS_MAX 200000u    // ~600k texels; a session's fine strokes stay far below
#define PRODUCT_FLOATS 12
_Static_assert(RS_COSMETIC_REGION_COUNT == 5, "shaders_es/makeup_fine.glsl: RS_FINE_REGIONS");

// The product as the shader composes it: linear colour, weights, finish, layers, tip hardness.
static void product_floats(const rs_cosmetic *c, float out[PRODUCT_FLOATS])
{
    float v[PRODUCT_FLOATS] = {rs_srgb_to_linear(c->rgb[0] / 255.0f), rs_srgb_to_linear(c->rgb[1] / 255.0f),
                               rs_srgb_to_linear(c->rgb[2] / 255.0f), RS_CLAMP(c->colour_weight, 0.0f, 1.0f),
                               RS_CLAMP(c->m, 0.0f, 1.0f), RS_CLAMP(c->rho_s, 0.0f, 1.0f),
                               RS_CLAMP(c->finish_weight, 0.0f, 1.0f), RS_CLAMP(c->material_weight, 0.0f, 1.0f),
                               RS_CLAMP(c->coat, 0.0f, 1.0f), RS_CLAMP(c->shimmer, 0.0f, 1.0f),
                               RS_CLAMP(c->coverage, 0.0f, 1.0f), rs_makeup_tip_hardness(c)};
    memcpy(out, v, sizeof v);
}

// (Re)allocates `tex` to hold `rows` rows when it holds fewer.
static void ensure_rows(GLuint *tex, int *have, int rows, GLenum format)
{
    if (*tex && *have >= rows) return;
    if (*tex) glDeleteTextures(1, tex);
    int alloc = 1;
    while (alloc < rows) alloc *= 2;
    *tex = rs_render_texture(format, FINE_TEX_WIDTH, alloc);
    *have = alloc;
}

static void upload_rows(GLuint tex, GLenum format, GLenum type, const void *data, size_t texels, size_t texel_bytes)
{
    glBindTexture(GL_TEXTURE_2D, tex);
    size_t full = texels / FINE_TEX_WIDTH, rest = texels % FINE_TEX_WIDTH;
    if (full) glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, FINE_TEX_WIDTH, (GLsizei)full, format, type, data);
    if (rest)
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, (GLint)full, (GLsizei)rest, 1, format, type,
                        (const uint8_t *)data + full * FINE_TEX_WIDTH * texel_bytes);
    glBindTexture(GL_TEXTURE_2D, 0);
}

static int cell_index(const rs_render_fine *g, const int c[3]) { return (c[2] * g->dim[1] + c[1]) * g->dim[0] + c[0]; }

// The cells [lo, hi] per axis that a stamp's bounding cube touches.
static void stamp_cells(const rs_render_fine *g, const rs_makeup_fine_stamp *s, int lo[3], int hi[3])
{
    for (int a = 0; a < 3; a++) {
        lo[a] = RS_CLAMP((int)floorf((s->pos[a] - s->radius - g->origin[a]) * g->inv_cell), 0, g->dim[a] - 1);
        hi[a] = RS_CLAMP((int)floorf((s->pos[a] + s->radius - g->origin[a]) * g->inv_cell), 0, g->dim[a] - 1);
    }
}

// The grid over the stamps and its lists (cells first, then the lists), as R32UI texels.
static uint32_t *build_index(rs_render_fine *g, const rs_makeup_fine_stamp *s, uint32_t n, size_t *texels)
{
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, rmax = 0.0f;
    for (uint32_t k = 0; k < n; k++) {
        rmax = fmaxf(rmax, s[k].radius);
        for (int a = 0; a < 3; a++)
            lo[a] = fminf(lo[a], s[k].pos[a] - s[k].radius), hi[a] = fmaxf(hi[a], s[k].pos[a] + s[k].radius);
    }
    // Cells fit the typical stamp (the median radius, from a histogram in quarter octaves below the
    // widest): a pixel looks at the stamps near it, not at every stamp within the widest one's reach (a
    // wide eraser or lipstick among liner stamps); a wider stamp is listed in every cell it reaches.
    enum { BINS = 64 };
    uint32_t bins[BINS] = {0};
    for (uint32_t k = 0; k < n; k++) {
        int b = s[k].radius > 0.0f ? (int)(-4.0f * log2f(s[k].radius / rmax)) : BINS - 1;
        bins[RS_CLAMP(b, 0, BINS - 1)]++;
    }
    int med = BINS - 1;
    for (uint32_t b = BINS, seen = 0; b-- > 0;)
        if ((seen += bins[b]) * 2 >= n) {
            med = (int)b;
            break;
        }
    float rtyp = rmax * exp2f(-0.25f * (float)med);
    float ext = fmaxf(fmaxf(hi[0] - lo[0], hi[1] - lo[1]), hi[2] - lo[2]);
    float cell = fmaxf(2.0f * rtyp, ext / (float)FINE_DIM_MAX) * 1.001f;
    g->inv_cell = 1.0f / cell;
    uint32_t cells = 1;
    for (int a = 0; a < 3; a++) {
        g->origin[a] = lo[a];
        g->dim[a] = RS_CLAMP((int)ceilf((hi[a] - lo[a]) * g->inv_cell), 1, FINE_DIM_MAX);
        cells *= (uint32_t)g->dim[a];
    }
    uint32_t *count = calloc(cells, sizeof *count);
    if (!count) return NULL;
    size_t entries = 0;
    int a0[3], a1[3], c[3];
    for (uint32_t k = 0; k < n; k++) {
        stamp_cells(g, &s[k], a0, a1);
        for (c[2] = a0[2]; c[2] <= a1[2]; c[2]++)
            for (c[1] = a0[1]; c[1] <= a1[1]; c[1]++)
                for (c[0] = a0[0]; c[0] <= a1[0]; c[0]++) count[cell_index(g, c)]++, entries++;
    }
    *texels = 2 * (size_t)cells + entries;
    uint32_t *out = rs_alloc_array(*texels, sizeof *out);
    if (!out) {
        free(count);
        return NULL;
    }
    uint32_t start = 2 * cells;
    for (uint32_t i = 0; i < cells; i++) {
        out[2 * i] = start, out[2 * i + 1] = 0;
        start += count[i];
    }
    // Filled in stamp order: each cell's list is in log order, as the shader's stacking needs.
    for (uint32_t k = 0; k < n; k++) {
        stamp_cells(g, &s[k], a0, a1);
        for (c[2] = a0[2]; c[2] <= a1[2]; c[2]++)
            for (c[1] = a0[1]; c[1] <= a1[1]; c[1]++)
                for (c[0] = a0[0]; c[0] <= a1[0]; c[0]++) {
                    int i = cell_index(g, c);
                    out[out[2 * i] + out[2 * i + 1]++] = k;
                }
    }
    free(count);
    return out;
}

// Marks dirty the stamps from the first that differs between the last upload and this one, in both.
static void mark_changed(rs_renderer *r, const rs_makeup_fine_stamp *s, uint32_t n)
{
    rs_render_fine *g = &r->fine;
    uint32_t same = 0;
    while (same < n && same < g->last_count && !memcmp(&s[same], &g->last[same], sizeof *s)) same++;
    for (uint32_t k = same; k < g->last_count; k++) rs_render_mark_dirty_sphere(r, g->last[k].pos, g->last[k].radius);
    for (uint32_t k = same; k < n; k++) rs_render_mark_dirty_sphere(r, s[k].pos, s[k].radius);
}

// The region masks' fields (makeup.c, "Region masks per pixel") stacked along z in one R8 3D texture,
// filtered linearly: the field between voxels is interpolated, so the mask's level set (the lip line) is
// smooth. A field never changes once built; a new one (the first stamp kept to a region) redraws all.
static void upload_fields(rs_renderer *r, const rs_makeup *mk)
{
    rs_render_fine *g = &r->fine;
    const rs_makeup_field *f[RS_COSMETIC_REGION_COUNT];
    bool same = true;
    int w = 1, h = 1, d = 0;
    for (int k = 0; k < RS_COSMETIC_REGION_COUNT; k++) {
        f[k] = mk ? rs_makeup_region_field(mk, (rs_cosmetic_region)k) : NULL;
        same = same && (f[k] ? f[k]->value : NULL) == g->field_value[k];
        if (f[k]) w = RS_MAX(w, f[k]->dim[0]), h = RS_MAX(h, f[k]->dim[1]), d += f[k]->dim[2];
    }
    if (same) return;
    rs_render_invalidate(r);
    if (g->field_tex) glDeleteTextures(1, &g->field_tex);
    g->field_tex = 0;
    memset(g->field_value, 0, sizeof g->field_value);
    memset(g->field_box, 0, sizeof g->field_box);
    if (d == 0) return;
    glGenTextures(1, &g->field_tex);
    glBindTexture(GL_TEXTURE_3D, g->field_tex);
    // At most two fields of 128 slices: within GLES 3's least GL_MAX_3D_TEXTURE_SIZE (256).
    glTexStorage3D(GL_TEXTURE_3D, 1, GL_R8, w, h, d);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
    GLint align;
    glGetIntegerv(GL_UNPACK_ALIGNMENT, &align);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    int z0 = 0;
    for (int k = 0; k < RS_COSMETIC_REGION_COUNT; k++) {
        if (!f[k]) continue;
        const int *n = f[k]->dim;
        glTexSubImage3D(GL_TEXTURE_3D, 0, 0, 0, z0, n[0], n[1], n[2], GL_RED, GL_UNSIGNED_BYTE, f[k]->value);
        float box[8] = {f[k]->origin[0], f[k]->origin[1], f[k]->origin[2], 1.0f / f[k]->voxel,
                        (float)n[0], (float)n[1], (float)n[2], (float)z0};
        memcpy(g->field_box[k], box, sizeof box);
        g->field_ramp[k][0] = f[k]->threshold, g->field_ramp[k][1] = f[k]->band;
        g->field_value[k] = f[k]->value;
        z0 += n[2];
    }
    glPixelStorei(GL_UNPACK_ALIGNMENT, align);
    glBindTexture(GL_TEXTURE_3D, 0);
}

rs_result rs_render_update_fine(rs_renderer *r, const rs_makeup_fine_stamp *s, uint32_t n, const rs_makeup *mk,
                                rs_error *err)
{
    rs_render_fine *g = &r->fine;
    if (n > FINE_STAMPS_MAX)
        return rs_fail(err, RS_ERR_LIMIT, "render: %u fine stamps (at most %u: save the look and clear)", n,
                       FINE_STAMPS_MAX);
    uint32_t np = mk ? rs_makeup_log_cosmetic_count(mk) : 0;  // no layer: no fine layer (n is 0)
    size_t stamp_texels = 3 * (size_t)n, data_texels = stamp_texels + 3 * (size_t)np, index_texels = 0;
    float *data = rs_alloc_array(RS_MAX(data_texels, 1u), 4 * sizeof(float));
    rs_makeup_fine_stamp *copy = rs_alloc_array(RS_MAX(n, 1u), sizeof *copy);
    uint32_t *index = n ? build_index(g, s, n, &index_texels) : NULL;
    if (!data || !copy || (n && !index)) {
        free(data), free(copy), free(index);
        return rs_fail(err, RS_ERR_NOMEM, "render: fine layer of %u stamps: out of memory", n);
    }
    for (uint32_t k = 0; k < n; k++) {
        float v[12] = {s[k].pos[0], s[k].pos[1], s[k].pos[2], s[k].radius,
                       s[k].view_dir[0], s[k].view_dir[1], s[k].view_dir[2], s[k].amount,
                       (float)s[k].cosmetic, (float)s[k].stroke, (float)s[k].eraser, (float)s[k].region};
        memcpy(data + 12 * (size_t)k, v, sizeof v);
    }
    for (uint32_t i = 0; i < np; i++) product_floats(rs_makeup_log_cosmetic(mk, i), data + 4 * stamp_texels + 12 * (size_t)i);
    // The products are known by index: when one changes (a look replaced), no rectangle says where.
    bool same_products = np == g->last_product_count &&
                         (np == 0 || !memcmp(g->last_products, data + 4 * stamp_texels, (size_t)np * PRODUCT_FLOATS * sizeof(float)));
    upload_fields(r, mk);
    if (!same_products) rs_render_invalidate(r);
    else if (r->inc_valid) mark_changed(r, s, n);
    if (n) {
        ensure_rows(&g->data_tex, &g->data_rows, (int)((data_texels + FINE_TEX_WIDTH - 1) / FINE_TEX_WIDTH), GL_RGBA32F);
        ensure_rows(&g->index_tex, &g->index_rows, (int)((index_texels + FINE_TEX_WIDTH - 1) / FINE_TEX_WIDTH), GL_R32UI);
        upload_rows(g->data_tex, GL_RGBA, GL_FLOAT, data, data_texels, 16);
        upload_rows(g->index_tex, GL_RED_INTEGER, GL_UNSIGNED_INT, index, index_texels, 4);
    }
    if (n) memcpy(copy, s, (size_t)n * sizeof *s);  // s is NULL when the layer has no fine stamps
    free(g->last);
    g->last = copy;
    g->last_count = n;
    free(g->last_products);
    g->last_products = rs_alloc_array(RS_MAX((size_t)np * PRODUCT_FLOATS, 1u), sizeof(float));
    g->last_product_count = g->last_products ? np : 0;
    if (g->last_products) memcpy(g->last_products, data + 4 * stamp_texels, (size_t)np * PRODUCT_FLOATS * sizeof(float));
    g->count = n;
    g->products = (uint32_t)stamp_texels;
    free(data);
    free(index);
    return rs_gl_check("render: fine layer upload", err);
}

void rs_render_fine_uniforms(const rs_renderer *r, const rs_frame *f, GLuint prog)
{
    const rs_render_fine *g = &r->fine;
    glUniform1i(rs_uloc(prog, "u_fine_count"), f->view.hide_makeup ? 0 : (GLint)g->count);
    glUniform1i(rs_uloc(prog, "u_fine_products"), (GLint)g->products);
    glUniform3fv(rs_uloc(prog, "u_fine_origin"), 1, g->origin);
    glUniform1f(rs_uloc(prog, "u_fine_inv_cell"), g->inv_cell);
    glUniform3i(rs_uloc(prog, "u_fine_dim"), g->dim[0], g->dim[1], g->dim[2]);
    glUniform3fv(rs_uloc(prog, "rs_makeup_range_lo"), 1, r->makeup_uni.range_lo);
    glUniform3fv(rs_uloc(prog, "rs_makeup_range_hi"), 1, r->makeup_uni.range_hi);
    glUniform1i(rs_uloc(prog, "u_fine_data"), RS_UNIT_FINE);
    glUniform1i(rs_uloc(prog, "u_fine_index"), RS_UNIT_FINE_INDEX);
    rs_render_bind_texture(RS_UNIT_FINE, g->count ? g->data_tex : 0);
    rs_render_bind_texture(RS_UNIT_FINE_INDEX, g->count ? g->index_tex : 0);
    glUniform1i(rs_uloc(prog, "u_fine_field"), RS_UNIT_FINE_FIELD);
    glUniform4fv(rs_uloc(prog, "u_fine_field_box"), 2 * RS_COSMETIC_REGION_COUNT, &g->field_box[0][0]);
    glUniform2fv(rs_uloc(prog, "u_fine_field_ramp"), RS_COSMETIC_REGION_COUNT, &g->field_ramp[0][0]);
    glActiveTexture(GL_TEXTURE0 + RS_UNIT_FINE_FIELD);
    glBindTexture(GL_TEXTURE_3D, g->count ? g->field_tex : 0);
}

void rs_render_fine_unbind(void)
{
    glActiveTexture(GL_TEXTURE0 + RS_UNIT_FINE_FIELD);
    glBindTexture(GL_TEXTURE_3D, 0);
}

void rs_render_fine_release(rs_renderer *r)
{
    rs_render_fine *g = &r->fine;
    GLuint t[3] = {g->data_tex, g->index_tex, g->field_tex};
    glDeleteTextures(3, t);
    free(g->last);
    free(g->last_products);
    memset(g, 0, sizeof *g);
}
