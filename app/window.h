// window.h — the viewer's window: a GLFW window with a GLES 3.0 context created through EGL.
//
// Does: open a window (or full screen) with GLFW_OPENGL_ES_API + GLFW_EGL_CONTEXT_API, make its context
// current, query its caps (rs_gl_query_caps), and say in one line why no window could be had.
// Does not: handle input or draw (app/viewer*.c); the library (src/) never sees GLFW.
//
//   rs_window *win;
//   if (rs_window_create(&(rs_window_desc){.width = 1024, .height = 768}, &win, &err)) return 1;
//   GLFWwindow *w = rs_window_glfw(win);   // events, swap
//   rs_window_destroy(win);
#ifndef RS_APP_WINDOW_H
#define RS_APP_WINDOW_H

#include "core/core.h"
#include "gl/gl.h"

typedef struct GLFWwindow GLFWwindow;

typedef struct rs_window_desc {
    int width, height;   // window size in screen coordinates (0: 1024 x 768)
    const char *title;   // NULL: "rouge"
    bool fullscreen;     // the primary monitor at its current video mode
} rs_window_desc;

typedef struct rs_window rs_window;

rs_result rs_window_create(const rs_window_desc *desc, rs_window **out, rs_error *err);
void rs_window_destroy(rs_window *win);
GLFWwindow *rs_window_glfw(const rs_window *win);
const rs_gl_caps *rs_window_caps(const rs_window *win);

#endif
