// window.c — see window.h.
#include "window.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <stdio.h>
#include <stdlib.h>

// Under AddressSanitizer the driver stays mapped at exit (see src/gl/gl.c): glfwTerminate unloads it.
#if defined(__SANITIZE_ADDRESS__)
#define RS_WINDOW_KEEP_DRIVER 1
#else
#define RS_WINDOW_KEEP_DRIVER 0
#endif

struct rs_window {
    GLFWwindow *glfw;
    rs_gl_caps caps;
};

// GLFW reports errors through a callback without user data; the app has one window at a time.
static char glfw_error_text[256];

static void glfw_on_error(int code, const char *text)
{
    snprintf(glfw_error_text, sizeof glfw_error_text, "%s (0x%x)", text, code);
}

rs_result rs_window_create(const rs_window_desc *desc, rs_window **out, rs_error *err)
{
    rs_window_desc d = desc ? *desc : (rs_window_desc){0};
    glfwSetErrorCallback(glfw_on_error);
    glfw_error_text[0] = 0;
    if (!glfwInit()) return rs_fail(err, RS_ERR_GL, "no window: GLFW init failed: %s", glfw_error_text);
    glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_ES_API);
    glfwWindowHint(GLFW_CONTEXT_CREATION_API, GLFW_EGL_CONTEXT_API);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 0);
    glfwWindowHint(GLFW_SCALE_TO_MONITOR, GLFW_TRUE);
    glfwWindowHint(GLFW_SAMPLES, 0);
    GLFWmonitor *mon = d.fullscreen ? glfwGetPrimaryMonitor() : NULL;
    int w = d.width > 0 ? d.width : 1024, h = d.height > 0 ? d.height : 768;
    if (mon) {
        const GLFWvidmode *mode = glfwGetVideoMode(mon);
        if (mode) w = mode->width, h = mode->height;
    }
    rs_window *win = calloc(1, sizeof *win);
    if (!win) {
        glfwTerminate();
        return rs_fail(err, RS_ERR_NOMEM, "out of memory");
    }
    win->glfw = glfwCreateWindow(w, h, d.title ? d.title : "rouge", mon, NULL);
    if (!win->glfw) {
        free(win);
        glfwTerminate();
        return rs_fail(err, RS_ERR_GL, "no GLES 3 window: %s", glfw_error_text[0] ? glfw_error_text : "unknown");
    }
    glfwMakeContextCurrent(win->glfw);
    glfwSwapInterval(1);
    snprintf(win->caps.platform, sizeof win->caps.platform, "GLFW window");
    rs_result r = rs_gl_query_caps(&win->caps, err);
    if (r != RS_OK) {
        rs_window_destroy(win);
        return r;
    }
    *out = win;
    return RS_OK;
}

void rs_window_destroy(rs_window *win)
{
    if (!win) return;
    glfwDestroyWindow(win->glfw);
    if (!RS_WINDOW_KEEP_DRIVER) glfwTerminate();
    free(win);
}

GLFWwindow *rs_window_glfw(const rs_window *win) { return win->glfw; }

const rs_gl_caps *rs_window_caps(const rs_window *win) { return &win->caps; }
