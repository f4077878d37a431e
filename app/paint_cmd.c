// paint_cmd.c — headless painting for `rouge render`: --look, then --strokes (replayed through the same
// paint session and ID-buffer picking the viewer uses), then --save-look.
#include "app.h"
#include "formats/look.h"
#include "paint/paint.h"

#include <stdlib.h>

// The picker sees the renderer through the view the stroke was recorded with.
typedef struct picker_ctx {
    rs_renderer *ren;
    rs_view view;
} picker_ctx;

static bool pick_cb(void *user, float x, float y, uint32_t *idx, float hit[3])
{
    picker_ctx *c = user;
    return rs_render_pick(c->ren, &c->view, x, y, idx, hit);
}

static float ppu_cb(void *user, const float pos[3])
{
    picker_ctx *c = user;
    return rs_render_pixels_per_unit(c->ren, &c->view, pos);
}

static void dir_cb(void *user, const float pos[3], float dir[3])
{
    picker_ctx *c = user;
    rs_render_view_dir(c->ren, &c->view, pos, dir);
}

static void apply_stroke_view(rs_view *v, const rs_strokes_view *s)
{
    v->yaw_deg = s->yaw_deg;
    v->pitch_deg = s->pitch_deg;
    v->zoom = s->zoom;
    v->fov_deg = s->fov_deg;
}

static rs_result replay(const rs_cli *cli, rs_makeup *mk, rs_renderer *ren, rs_view *view, rs_error *err)
{
    rs_strokes *doc = NULL;
    rs_result r = rs_strokes_load(cli->strokes, &doc, err);
    if (r) return r;
    picker_ctx ctx = {.ren = ren, .view = *view};
    rs_paint_picker pk = {.user = &ctx, .pick = pick_cb, .pixels_per_unit = ppu_cb, .view_dir = dir_cb};
    rs_paint *pt = NULL;
    r = rs_paint_create(mk, &pk, &(rs_paint_desc){.input.mode = RS_INPUT_PAINT}, &pt, err);
    for (uint32_t i = 0; !r && i < doc->count; i++) {
        const rs_strokes_stroke *s = &doc->strokes[i];
        // Pick in the frame the stroke was recorded in: same camera, same pixel grid.
        apply_stroke_view(&ctx.view, &s->view);
        ctx.view.width = (int)s->view.width_px;
        ctx.view.height = (int)s->view.height_px;
        rs_paint_result res;
        r = rs_paint_replay(pt, doc, i, s->view.width_px, s->view.height_px, &res, err);
    }
    // The output shows the face as the artist saw it, unless the command line chose a view.
    if (!r && doc->count > 0) {
        rs_view rec = *view;
        apply_stroke_view(&rec, &doc->strokes[doc->count - 1].view);
        if (!cli->view_set[0]) view->yaw_deg = rec.yaw_deg;
        if (!cli->view_set[1]) view->pitch_deg = rec.pitch_deg;
        if (!cli->view_set[2]) view->zoom = rec.zoom;
        if (!cli->view_set[3]) view->fov_deg = rec.fov_deg;
    }
    rs_paint_destroy(pt);
    rs_strokes_destroy(doc);
    return r;
}

rs_result rs_app_apply_painting(const rs_cli *cli, const rs_splat_cloud *cloud, rs_renderer *ren, rs_view *view,
                                rs_error *err)
{
    if (!cli->look && !cli->strokes) {
        if (cli->save_look) return rs_fail(err, RS_ERR_ARG, "--save-look needs --look or --strokes to save");
        return RS_OK;
    }
    rs_makeup *mk = NULL;
    rs_result r = rs_makeup_create(cloud, NULL, &mk, err);
    if (r) return r;
    rs_makeup_range dirty;
    if (cli->look) r = rs_look_load(mk, cli->look, &dirty, err);
    if (!r && cli->strokes) r = replay(cli, mk, ren, view, err);
    if (!r && cli->save_look) r = rs_look_save(mk, cli->save_look, err);
    if (!r) {
        rs_makeup_uniforms u;
        rs_makeup_get_uniforms(mk, &u);
        rs_render_set_makeup_uniforms(ren, &u);
        r = rs_render_update_makeup(ren, 0, rs_makeup_count(mk), rs_makeup_records(mk), err);
    }
    rs_makeup_destroy(mk);
    return r;
}
