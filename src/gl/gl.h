// gl.h — a headless GLES 3.0 context (EGL) and the capabilities that every render path branches on.
//
// Does: headless contexts through EGL_MESA_platform_surfaceless (Mesa, llvmpipe) falling back to
// EGL_EXT_platform_device (NVIDIA and other drivers without a display); a one-line error naming each
// platform tried and why it failed; the caps struct (float render targets, point size range, MRT
// count...), also for a context a host application made (rs_gl_query_caps).
// Does not: open windows (the app's window.c does, with GLFW), render anything, or own GL objects other
// than the context.
//
//   rs_gl_context *gl;
//   if (rs_gl_create(&(rs_gl_desc){0}, &gl, &err) != RS_OK) { fprintf(stderr, "%s\n", err.msg); exit(1); }
//   const rs_gl_caps *caps = rs_gl_get_caps(gl);
//   ... render into an FBO ...
//   rs_gl_destroy(gl);
#ifndef RS_GL_GL_H
#define RS_GL_GL_H

#include "core/core.h"

#include <GLES3/gl3.h>

typedef struct rs_gl_caps {
    int major, minor;               // GLES version of the context
    char renderer[128];             // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
    char version[128];              // GL_VERSION
    char platform[32];              // "EGL surfaceless", "EGL device", "GLFW window", "host context"
    bool float_rt;                  // RGBA16F colour attachments with blending (EXT_color_buffer_*_float)
    float point_size_max;           // GL_ALIASED_POINT_SIZE_RANGE[1]
    int max_draw_buffers;
    int max_texture_size;
    int max_vertex_texture_units;
} rs_gl_caps;

typedef enum rs_gl_platform {
    RS_GL_AUTO = 0,      // surfaceless first, then EGL devices
    RS_GL_SURFACELESS,   // EGL_MESA_platform_surfaceless only
    RS_GL_DEVICE,        // EGL_EXT_platform_device only
} rs_gl_platform;

typedef struct rs_gl_desc {
    rs_gl_platform platform;
} rs_gl_desc;

typedef struct rs_gl_context rs_gl_context;

rs_result rs_gl_create(const rs_gl_desc *desc, rs_gl_context **out, rs_error *err);
void rs_gl_destroy(rs_gl_context *ctx);
const rs_gl_caps *rs_gl_get_caps(const rs_gl_context *ctx);
// Fills `caps` from the current context (any platform: a host's own, a GLFW window's). caps->platform is
// kept when set, else "host context". RS_ERR_GL when no context is current or it is not GLES 3.
rs_result rs_gl_query_caps(rs_gl_caps *caps, rs_error *err);

// Returns RS_ERR_GL naming `where` if glGetError reports an error.
rs_result rs_gl_check(const char *where, rs_error *err);

#endif
