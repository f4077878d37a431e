// face_fixture.c — see face_fixture.h.
#include "support/face_fixture.h"
#include "support/harness.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

bool rs_test_face_open(const char *name, rs_test_face *tf)
{
    rs_error err = {0};
    memset(tf, 0, sizeof *tf);
    if (rs_gl_create(&(rs_gl_desc){0}, &tf->gl, &err) != RS_OK) {
        printf("FAIL - %s_gl_context: %s\n", name, err.msg);
        return false;
    }
    const char *path = getenv("RS_TEST_FACE");
    if (!path || !*path) path = "assets/face.rsf";
    if (rs_splat_load(path, &tf->cloud, &err) != RS_OK) {
        snprintf(tf->why, sizeof tf->why, "no test face: %s", err.msg);
        tf->cloud = NULL;
        return true;
    }
    if (rs_render_create(&(rs_render_desc){.cloud = tf->cloud, .caps = rs_gl_get_caps(tf->gl)}, &tf->ren, &err) !=
        RS_OK) {
        printf("FAIL - %s_render_create: %s\n", name, err.msg);
        rs_test_face_close(tf);
        return false;
    }
    return true;
}

void rs_test_face_close(rs_test_face *tf)
{
    rs_render_destroy(tf->ren);
    rs_splat_destroy(tf->cloud);
    rs_gl_destroy(tf->gl);
    memset(tf, 0, sizeof *tf);
}

bool rs_test_face_ready(const rs_test_face *tf)
{
    if (tf->cloud && tf->ren) return true;
    rs_test_skip("%s", tf->why);
    return false;
}

bool rs_test_render(rs_renderer *ren, const rs_view *v, rs_image *img)
{
    rs_error err = {0};
    return RS_CHECK(rs_render_image(ren, v, img, &err) == RS_OK, "render: %s", err.msg);
}

int rs_test_count_holes(const rs_image *img, const uint8_t bg[3], int *face_px)
{
    int w = img->width, h = img->height, n = w * h, ch = img->channels;
    uint8_t *seen = calloc((size_t)n, 1), *is_bg = malloc((size_t)n);
    int *stack = malloc(sizeof(int) * ((size_t)n * 4 + 2 * (size_t)(w + h) + 64));  // every push: border or a neighbour of a popped pixel
    if (!seen || !is_bg || !stack) {
        free(seen), free(is_bg), free(stack);
        return -1;
    }
    for (int i = 0; i < n; i++) is_bg[i] = !memcmp(img->pixels + (size_t)i * (size_t)ch, bg, 3);
    int sp = 0;
    for (int x = 0; x < w; x++) stack[sp++] = x, stack[sp++] = (h - 1) * w + x;
    for (int y = 0; y < h; y++) stack[sp++] = y * w, stack[sp++] = y * w + w - 1;
    while (sp) {
        int i = stack[--sp];
        if (seen[i] || !is_bg[i]) continue;
        seen[i] = 1;
        int x = i % w, y = i / w;
        if (x > 0) stack[sp++] = i - 1;
        if (x < w - 1) stack[sp++] = i + 1;
        if (y > 0) stack[sp++] = i - w;
        if (y < h - 1) stack[sp++] = i + w;
    }
    int holes = 0, fg = 0;
    for (int i = 0; i < n; i++) {
        fg += !is_bg[i];
        holes += is_bg[i] && !seen[i];
    }
    free(seen), free(is_bg), free(stack);
    *face_px = fg;
    return holes;
}
