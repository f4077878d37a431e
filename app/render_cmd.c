// render_cmd.c — `rouge render`: headless EGL render of a face (optionally painted) to a PNG.
#include "app.h"

#include <string.h>

rs_result rs_app_render(const rs_cli *cli, rs_error *err)
{
    if (!cli->face) return rs_fail(err, RS_ERR_ARG, "render: no face file given (usage: rouge render FACE.rsf -o OUT.png)");
    if (!cli->output) return rs_fail(err, RS_ERR_ARG, "render: no output given (-o OUT.png)");
    rs_splat_cloud *cloud = NULL;
    rs_result r = rs_splat_load(cli->face, &cloud, err);
    if (r) return r;
    rs_gl_context *gl = NULL;
    rs_renderer *ren = NULL;
    rs_image img = {0};
    rs_view view = cli->view;
    r = rs_gl_create(&(rs_gl_desc){0}, &gl, err);
    if (!r) r = rs_render_create(&(rs_render_desc){.cloud = cloud, .caps = rs_gl_get_caps(gl)}, &ren, err);
    if (!r) r = rs_app_apply_painting(cli, cloud, ren, &view, err);
    if (!r) r = rs_render_image(ren, &view, &img, err);
    if (!r) r = rs_image_write_png(cli->output, &img, err);
    rs_image_free(&img);
    rs_render_destroy(ren);
    rs_gl_destroy(gl);
    rs_splat_destroy(cloud);
    return r;
}
