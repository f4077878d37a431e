// face_fixture.h — what the renderer tests share: a headless GL context, the test face (RS_TEST_FACE or
// assets/face.rsf) with its renderer, one render call that reports failures, and the hole count.
//
//   static rs_test_face tf;
//   if (!rs_test_face_open("render", &tf)) return 1;   // a FAIL line was printed
//   ... if (!rs_test_face_ready(&tf)) return;           // a skip line when the face is missing
//   rs_test_face_close(&tf);
#ifndef RS_TEST_FACE_FIXTURE_H
#define RS_TEST_FACE_FIXTURE_H

#include "core/image.h"
#include "gl/gl.h"
#include "render/render.h"
#include "splat/splat.h"

typedef struct rs_test_face {
    rs_gl_context *gl;
    rs_splat_cloud *cloud;  // NULL when the face could not be loaded (why says so; tests skip)
    rs_renderer *ren;
    char why[600];
} rs_test_face;

// False after printing "FAIL - NAME_gl_context / NAME_render_create" when there is no context or renderer;
// a face that does not load is no failure (cloud stays NULL).
bool rs_test_face_open(const char *name, rs_test_face *tf);
void rs_test_face_close(rs_test_face *tf);
// True with a face and renderer; otherwise prints the skip line.
bool rs_test_face_ready(const rs_test_face *tf);
// rs_render_image with a FAIL line on error.
bool rs_test_render(rs_renderer *ren, const rs_view *v, rs_image *img);
// Pixels equal to bg (RGB) that the image border cannot reach through other bg pixels: holes in the
// silhouette. *face_px counts the pixels that are not bg. -1 when out of memory.
int rs_test_count_holes(const rs_image *img, const uint8_t bg[3], int *face_px);

#endif
