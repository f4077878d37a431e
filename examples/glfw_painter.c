// glfw_painter.c — a minimal makeup painter: a GLFW window with a GLES 3 context, the face drawn into it
// by rouge, the mouse (or a touch screen's emulated mouse) painting, the wheel zooming.
//
//   cc glfw_painter.c $(pkg-config --cflags --libs rouge glfw3) -o glfw_painter
//   ./glfw_painter face.rsf [look-file]
//
// Left drag paints (or orbits after P), right drag orbits, wheel zooms at the cursor. Keys: 1-9 pick a
// cosmetic, E eraser, M mirror, P paint / orbit, Ctrl+Z / Ctrl+Y undo / redo, Delete clears,
// Ctrl+S saves the look (to the second argument, default painter.look), Esc quits.
// Written only against <rouge.h> and GLFW: rouge draws into the window's framebuffer and restores the GL
// state it touched, so a host can draw its own UI around it with no GL bookkeeping.
#include <rouge.h>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <stdio.h>
#include <string.h>

typedef struct painter {
    rouge_face *face;
    rouge_brush brush;
    const char *look_path;
    double px_per_pt;      // framebuffer pixels per window coordinate (HiDPI)
    double mx, my;         // cursor, framebuffer pixels
    bool orbiting;         // right button held
    bool painting;         // left button paints (else it orbits)
} painter;

static void report(const char *what, rouge_result r, const rouge_error *err)
{
    if (r != ROUGE_OK) fprintf(stderr, "glfw_painter: %s: %s\n", what, err->msg);
}

static void set_brush(painter *p)
{
    rouge_error err;
    report("brush", rouge_face_set_brush(p->face, &p->brush, &err), &err);
}

static void pointer(painter *p, rouge_pointer_type type)
{
    rouge_error err;
    rouge_pointer_event ev = {.type = type, .id = 0, .x = (float)p->mx, .y = (float)p->my, .time_s = glfwGetTime()};
    report("pointer", rouge_face_pointer(p->face, &ev, NULL, &err), &err);
}

static void on_cursor(GLFWwindow *w, double x, double y)
{
    painter *p = glfwGetWindowUserPointer(w);
    double dx = x * p->px_per_pt - p->mx, dy = y * p->px_per_pt - p->my;
    p->mx = x * p->px_per_pt, p->my = y * p->px_per_pt;
    if (glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS) pointer(p, ROUGE_POINTER_MOVE);
    if (p->orbiting) rouge_face_orbit(p->face, (float)(-dx * 0.3), (float)(dy * 0.3));
}

static void on_button(GLFWwindow *w, int button, int action, int mods)
{
    (void)mods;
    painter *p = glfwGetWindowUserPointer(w);
    if (button == GLFW_MOUSE_BUTTON_LEFT) pointer(p, action == GLFW_PRESS ? ROUGE_POINTER_DOWN : ROUGE_POINTER_UP);
    if (button == GLFW_MOUSE_BUTTON_RIGHT) p->orbiting = action == GLFW_PRESS;
}

static void on_scroll(GLFWwindow *w, double dx, double dy)
{
    (void)dx;
    painter *p = glfwGetWindowUserPointer(w);
    rouge_face_zoom_at(p->face, dy > 0 ? 1.1f : 1 / 1.1f, (float)p->mx, (float)p->my);
}

static void on_key(GLFWwindow *w, int key, int scancode, int action, int mods)
{
    (void)scancode;
    painter *p = glfwGetWindowUserPointer(w);
    if (action == GLFW_RELEASE) return;
    rouge_error err;
    bool ctrl = mods & GLFW_MOD_CONTROL;
    rouge_cosmetic c;
    if (key >= GLFW_KEY_1 && key <= GLFW_KEY_9 && rouge_cosmetic_get(key - GLFW_KEY_1, &c)) {
        p->brush = (rouge_brush){.cosmetic = c.name, .mirror = p->brush.mirror};
        set_brush(p);
        printf("brush: %s\n", c.name);
    } else if (key == GLFW_KEY_E) {
        p->brush.eraser = !p->brush.eraser, set_brush(p);
    } else if (key == GLFW_KEY_M) {
        p->brush.mirror = !p->brush.mirror, set_brush(p);
    } else if (key == GLFW_KEY_P) {
        p->painting = !p->painting;
        rouge_face_set_painting(p->face, p->painting);
    } else if (key == GLFW_KEY_Z && ctrl) {
        rouge_face_undo(p->face);
    } else if (key == GLFW_KEY_Y && ctrl) {
        rouge_face_redo(p->face);
    } else if (key == GLFW_KEY_DELETE) {
        report("clear", rouge_face_clear(p->face, &err), &err);
    } else if (key == GLFW_KEY_S && ctrl) {
        rouge_result r = rouge_face_save_look(p->face, p->look_path, &err);
        report("save", r, &err);
        if (r == ROUGE_OK) printf("saved %s\n", p->look_path);
    } else if (key == GLFW_KEY_ESCAPE) {
        glfwSetWindowShouldClose(w, GLFW_TRUE);
    }
}

int main(int argc, char **argv)
{
    if (argc < 2 || argc > 3) {
        fprintf(stderr, "usage: glfw_painter FACE.rsf [LOOK]\n");
        return 2;
    }
    if (!glfwInit()) return fprintf(stderr, "glfw_painter: no display\n"), 1;
    // rouge needs OpenGL ES 3.0; EGL gives it on X11, Wayland and embedded boards alike.
    glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_ES_API);
    glfwWindowHint(GLFW_CONTEXT_CREATION_API, GLFW_EGL_CONTEXT_API);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 0);
    GLFWwindow *win = glfwCreateWindow(800, 800, "rouge painter", NULL, NULL);
    if (!win) return fprintf(stderr, "glfw_painter: no GLES 3 window\n"), glfwTerminate(), 1;
    glfwMakeContextCurrent(win);
    glfwSwapInterval(1);

    painter p = {.look_path = argc > 2 ? argv[2] : "painter.look", .painting = true,
                 .brush = {.cosmetic = "lipstick_satin"}};
    rouge_error err;
    rouge_caps caps;
    if (rouge_query_caps(&caps, &err) == ROUGE_OK) printf("GLES %d.%d on %s\n", caps.gles_major, caps.gles_minor, caps.renderer);
    rouge_result r = rouge_face_create(&(rouge_face_desc){.path = argv[1]}, &p.face, &err);
    if (r == ROUGE_OK && argc > 2) {
        rouge_result lr = rouge_face_load_look(p.face, argv[2], &err);
        if (lr != ROUGE_OK) fprintf(stderr, "glfw_painter: %s (starting bare)\n", err.msg);
    }
    if (r == ROUGE_OK) {
        set_brush(&p);
        glfwSetWindowUserPointer(win, &p);
        glfwSetCursorPosCallback(win, on_cursor);
        glfwSetMouseButtonCallback(win, on_button);
        glfwSetScrollCallback(win, on_scroll);
        glfwSetKeyCallback(win, on_key);
    }
    int last_w = 0, last_h = 0;
    while (r == ROUGE_OK && !glfwWindowShouldClose(win)) {
        int w, h, ww, wh;
        glfwGetFramebufferSize(win, &w, &h);
        glfwGetWindowSize(win, &ww, &wh);
        p.px_per_pt = ww > 0 ? (double)w / ww : 1.0;
        // Redraw only when something changed: an idle painter costs nothing.
        if (w > 0 && h > 0 && (rouge_face_changed(p.face) || w != last_w || h != last_h)) {
            r = rouge_face_draw(p.face, 0, 0, w, h, &err);
            glfwSwapBuffers(win);
            last_w = w, last_h = h;
        }
        glfwWaitEventsTimeout(0.5);
    }
    if (r != ROUGE_OK) fprintf(stderr, "glfw_painter: %s\n", err.msg);
    rouge_face_destroy(p.face);
    glfwDestroyWindow(win);
    glfwTerminate();
    return r == ROUGE_OK ? 0 : 1;
}
