// gl.c — see gl.h.
#include "gl/gl.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// Under AddressSanitizer the driver stays mapped at exit: Mesa unloads it in eglTerminate,
// after which LeakSanitizer cannot name (and tests/lsan.supp cannot suppress) the driver's own leaks.
#if defined(__SANITIZE_ADDRESS__)
#define RS_GL_KEEP_DRIVER 1
#else
#define RS_GL_KEEP_DRIVER 0
#endif

struct rs_gl_context {
    rs_gl_caps caps;
    EGLDisplay dpy;
    EGLContext ctx;
};

static const char *egl_error_name(EGLint e)
{
    switch (e) {
    case EGL_SUCCESS: return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    default: return "EGL error";
    }
}

static bool has_ext(const char *list, const char *name)
{
    size_t n = strlen(name);
    for (const char *p = list; p && (p = strstr(p, name)); p += n)
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == 0)) return true;
    return false;
}

// Makes a GLES 3 context current on `dpy` without a surface. Writes why it failed into `why`.
static bool egl_try_display(rs_gl_context *c, EGLDisplay dpy, char *why, size_t why_len)
{
    EGLint major, minor;
    if (!eglInitialize(dpy, &major, &minor)) {
        snprintf(why, why_len, "eglInitialize: %s", egl_error_name(eglGetError()));
        return false;
    }
    const char *exts = eglQueryString(dpy, EGL_EXTENSIONS);
    if (!has_ext(exts, "EGL_KHR_surfaceless_context")) {
        snprintf(why, why_len, "no EGL_KHR_surfaceless_context");
        eglTerminate(dpy);
        return false;
    }
    // Surfaceless configs have no window bit, which eglChooseConfig asks for by default.
    const EGLint cfg_attr[] = {EGL_SURFACE_TYPE, 0, EGL_RENDERABLE_TYPE, EGL_OPENGL_ES3_BIT, EGL_NONE};
    EGLConfig cfg;
    EGLint ncfg = 0;
    if (!eglChooseConfig(dpy, cfg_attr, &cfg, 1, &ncfg) || ncfg < 1) {
        snprintf(why, why_len, "no EGL config with GLES 3 (%s)", egl_error_name(eglGetError()));
        eglTerminate(dpy);
        return false;
    }
    if (!eglBindAPI(EGL_OPENGL_ES_API)) {
        snprintf(why, why_len, "eglBindAPI(GLES): %s", egl_error_name(eglGetError()));
        eglTerminate(dpy);
        return false;
    }
    const EGLint ctx_attr[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 0, EGL_NONE};
    EGLContext ctx = eglCreateContext(dpy, cfg, EGL_NO_CONTEXT, ctx_attr);
    if (ctx == EGL_NO_CONTEXT) {
        snprintf(why, why_len, "GLES 3.0 context refused (%s)", egl_error_name(eglGetError()));
        eglTerminate(dpy);
        return false;
    }
    if (!eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) {
        snprintf(why, why_len, "eglMakeCurrent: %s", egl_error_name(eglGetError()));
        eglDestroyContext(dpy, ctx);
        eglTerminate(dpy);
        return false;
    }
    c->dpy = dpy;
    c->ctx = ctx;
    return true;
}

static rs_result create_headless(rs_gl_context *c, rs_gl_platform want, rs_error *err)
{
    const char *client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!client) return rs_fail(err, RS_ERR_GL, "no GLES 3 context: EGL has no client extensions (EGL 1.5 or "
                                                 "EGL_EXT_client_extensions needed)");
    PFNEGLGETPLATFORMDISPLAYEXTPROC get_display =
        (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
    char why_sl[160] = "EGL_MESA_platform_surfaceless not offered";
    char why_dev[160] = "EGL_EXT_platform_device not offered";
    if (want == RS_GL_DEVICE) snprintf(why_sl, sizeof why_sl, "not asked for");
    else if (get_display && has_ext(client, "EGL_MESA_platform_surfaceless")) {
        EGLDisplay dpy = get_display(EGL_PLATFORM_SURFACELESS_MESA, NULL, NULL);
        if (dpy == EGL_NO_DISPLAY) snprintf(why_sl, sizeof why_sl, "no display (%s)", egl_error_name(eglGetError()));
        else if (egl_try_display(c, dpy, why_sl, sizeof why_sl)) {
            snprintf(c->caps.platform, sizeof c->caps.platform, "EGL surfaceless");
            return RS_OK;
        }
    }
    PFNEGLQUERYDEVICESEXTPROC query_devices = (PFNEGLQUERYDEVICESEXTPROC)eglGetProcAddress("eglQueryDevicesEXT");
    if (want == RS_GL_SURFACELESS) snprintf(why_dev, sizeof why_dev, "not asked for");
    else if (get_display && query_devices && has_ext(client, "EGL_EXT_platform_device")) {
        EGLDeviceEXT devs[16];
        EGLint ndev = 0;
        if (!query_devices(16, devs, &ndev) || ndev == 0) snprintf(why_dev, sizeof why_dev, "no EGL devices");
        for (EGLint i = 0; i < ndev; i++) {
            EGLDisplay dpy = get_display(EGL_PLATFORM_DEVICE_EXT, devs[i], NULL);
            if (dpy != EGL_NO_DISPLAY && egl_try_display(c, dpy, why_dev, sizeof why_dev)) {
                snprintf(c->caps.platform, sizeof c->caps.platform, "EGL device");
                return RS_OK;
            }
        }
    }
    return rs_fail(err, RS_ERR_GL, "no GLES 3 context: surfaceless: %s; device: %s", why_sl, why_dev);
}

rs_result rs_gl_query_caps(rs_gl_caps *caps, rs_error *err)
{
    // Without a current context GL calls are no-ops that return NULL/0 (glvnd dispatch).
    if (!glGetString(GL_VERSION)) return rs_fail(err, RS_ERR_GL, "no current GL context to query");
    char platform[sizeof caps->platform];
    memcpy(platform, caps->platform, sizeof platform);
    memset(caps, 0, sizeof *caps);
    memcpy(caps->platform, platform, sizeof platform);
    if (!caps->platform[0]) snprintf(caps->platform, sizeof caps->platform, "host context");
    const char *ver = (const char *)glGetString(GL_VERSION);
    const char *ren = (const char *)glGetString(GL_RENDERER);
    snprintf(caps->version, sizeof caps->version, "%s", ver ? ver : "?");
    snprintf(caps->renderer, sizeof caps->renderer, "%s", ren ? ren : "?");
    glGetIntegerv(GL_MAJOR_VERSION, &caps->major);
    glGetIntegerv(GL_MINOR_VERSION, &caps->minor);
    GLint n = 0;
    glGetIntegerv(GL_NUM_EXTENSIONS, &n);
    bool half = false, full = false;
    for (GLint i = 0; i < n; i++) {
        const char *e = (const char *)glGetStringi(GL_EXTENSIONS, (GLuint)i);
        if (!e) continue;
        if (!strcmp(e, "GL_EXT_color_buffer_half_float")) half = true;
        if (!strcmp(e, "GL_EXT_color_buffer_float")) full = true;
    }
    // GLES 3.2 made float colour buffers core.
    caps->float_rt = half || full || caps->major > 3 || (caps->major == 3 && caps->minor >= 2);
    GLfloat range[2] = {1, 1};
    glGetFloatv(GL_ALIASED_POINT_SIZE_RANGE, range);
    caps->point_size_max = range[1];
    glGetIntegerv(GL_MAX_DRAW_BUFFERS, &caps->max_draw_buffers);
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &caps->max_texture_size);
    glGetIntegerv(GL_MAX_VERTEX_TEXTURE_IMAGE_UNITS, &caps->max_vertex_texture_units);
    if (caps->major < 3)
        return rs_fail(err, RS_ERR_GL, "no GLES 3 context: %s gave GLES %d.%d (%s)", caps->platform, caps->major,
                       caps->minor, caps->version);
    return RS_OK;
}

rs_result rs_gl_create(const rs_gl_desc *desc, rs_gl_context **out, rs_error *err)
{
    rs_gl_desc d = desc ? *desc : (rs_gl_desc){0};
    rs_gl_context *c = calloc(1, sizeof *c);
    if (!c) return rs_fail(err, RS_ERR_NOMEM, "out of memory");
    rs_result r = create_headless(c, d.platform, err);
    if (r != RS_OK) {
        free(c);
        return r;
    }
    r = rs_gl_query_caps(&c->caps, err);
    if (r != RS_OK) {
        rs_gl_destroy(c);
        return r;
    }
    *out = c;
    return RS_OK;
}

void rs_gl_destroy(rs_gl_context *c)
{
    if (!c) return;
    if (c->dpy) {
        eglMakeCurrent(c->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(c->dpy, c->ctx);
        if (!RS_GL_KEEP_DRIVER) eglTerminate(c->dpy);
    }
    free(c);
}

const rs_gl_caps *rs_gl_get_caps(const rs_gl_context *c) { return &c->caps; }

rs_result rs_gl_check(const char *where, rs_error *err)
{
    GLenum e = glGetError();
    if (e == GL_NO_ERROR) return RS_OK;
    while (glGetError() != GL_NO_ERROR) {
    }
    return rs_fail(err, RS_ERR_GL, "%s: GL error 0x%04x", where, e);
}
