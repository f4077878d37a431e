// embed_headless.c — rouge in a program without a window: make a GLES 3 context with EGL, load a face,
// paint one lipstick stroke across the lips, write the picture as a PNG.
//
//   cc embed_headless.c $(pkg-config --cflags --libs rouge egl libpng) -o embed_headless
//   ./embed_headless face.rsf out.png
//
// Written only against <rouge.h> (plus EGL for the context and libpng for the file), as any host would.
#include <rouge.h>

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>

#define SIZE 256  // small enough for a test to run it in a second on a software GL

// A context with no surface: Mesa's surfaceless platform (software or GPU), else the first EGL device
// (NVIDIA without a display). rouge renders into its own framebuffers, so no surface is needed.
static EGLDisplay open_display(void)
{
    PFNEGLGETPLATFORMDISPLAYEXTPROC get_display =
        (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
    PFNEGLQUERYDEVICESEXTPROC query_devices = (PFNEGLQUERYDEVICESEXTPROC)eglGetProcAddress("eglQueryDevicesEXT");
    EGLDisplay dpy = get_display ? get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL) : EGL_NO_DISPLAY;
    if (dpy != EGL_NO_DISPLAY && eglInitialize(dpy, NULL, NULL)) return dpy;
    EGLDeviceEXT dev;
    EGLint n = 0;
    if (get_display && query_devices && query_devices(1, &dev, &n) && n > 0) {
        dpy = get_display(EGL_PLATFORM_DEVICE_EXT, dev, NULL);
        if (dpy != EGL_NO_DISPLAY && eglInitialize(dpy, NULL, NULL)) return dpy;
    }
    return EGL_NO_DISPLAY;
}

static int make_context(EGLDisplay dpy)
{
    const EGLint cfg_attr[] = {EGL_SURFACE_TYPE, 0, EGL_RENDERABLE_TYPE, EGL_OPENGL_ES3_BIT, EGL_NONE};
    const EGLint ctx_attr[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_NONE};
    EGLConfig cfg;
    EGLint n = 0;
    if (!eglBindAPI(EGL_OPENGL_ES_API) || !eglChooseConfig(dpy, cfg_attr, &cfg, 1, &n) || n < 1) return 0;
    EGLContext ctx = eglCreateContext(dpy, cfg, EGL_NO_CONTEXT, ctx_attr);
    return ctx != EGL_NO_CONTEXT && eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx);
}

static int write_png(const char *path, const unsigned char *rgba, int w, int h)
{
    png_image img = {.version = PNG_IMAGE_VERSION, .width = (png_uint_32)w, .height = (png_uint_32)h,
                     .format = PNG_FORMAT_RGBA};
    return png_image_write_to_file(&img, path, 0, rgba, 0, NULL);
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: embed_headless FACE.rsf OUT.png\n");
        return 2;
    }
    EGLDisplay dpy = open_display();
    if (dpy == EGL_NO_DISPLAY || !make_context(dpy)) {
        fprintf(stderr, "embed_headless: no GLES 3 context (EGL error 0x%x)\n", eglGetError());
        return 1;
    }
    rouge_error err;
    rouge_face *face = NULL;
    rouge_view view = {.width = SIZE, .height = SIZE};  // everything else: the defaults (mobile pipeline)
    if (rouge_face_create(&(rouge_face_desc){.path = argv[1], .view = &view}, &face, &err) != ROUGE_OK) {
        fprintf(stderr, "embed_headless: %s\n", err.msg);
        return 1;
    }
    // Pointer coordinates refer to the last frame: render once, then find the lips down the middle.
    rouge_result r = rouge_face_render(face, &err);
    float lips_y = -1;
    rouge_pick pick;
    for (int y = SIZE / 2; r == ROUGE_OK && y < SIZE && lips_y < 0; y += SIZE / 128)
        if (rouge_face_pick(face, SIZE / 2, (float)y, &pick) && pick.region == 4) lips_y = (float)y + SIZE * 0.012f;
    if (r == ROUGE_OK && lips_y < 0) lips_y = SIZE * 0.62f;  // a face without a lips region
    if (r == ROUGE_OK) r = rouge_face_set_brush(face, &(rouge_brush){.cosmetic = "lipstick_satin", .size = 0.05f}, &err);
    // One stroke: finger down left of the mouth centre, twenty moves to the right, finger up.
    for (int i = 0; r == ROUGE_OK && i <= 20; i++) {
        rouge_pointer_event ev = {.type = i == 0 ? ROUGE_POINTER_DOWN : i == 20 ? ROUGE_POINTER_UP : ROUGE_POINTER_MOVE,
                                  .x = SIZE * (0.44f + 0.12f * (float)i / 20), .y = lips_y, .time_s = i / 60.0};
        r = rouge_face_pointer(face, &ev, NULL, &err);
    }
    unsigned char *rgba = malloc(SIZE * SIZE * 4);
    if (r == ROUGE_OK) r = rouge_face_render(face, &err);
    if (r == ROUGE_OK) r = rgba ? rouge_face_read_rgba(face, rgba, SIZE * SIZE * 4, &err) : ROUGE_ERR_NOMEM;
    int ok = r == ROUGE_OK && write_png(argv[2], rgba, SIZE, SIZE);
    if (r != ROUGE_OK) fprintf(stderr, "embed_headless: %s\n", r == ROUGE_ERR_NOMEM ? "out of memory" : err.msg);
    else if (!ok) fprintf(stderr, "embed_headless: cannot write %s\n", argv[2]);
    free(rgba);
    rouge_face_destroy(face);
    eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglTerminate(dpy);
    return ok ? 0 : 1;
}
