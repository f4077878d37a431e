// looks_cmd.c — `rouge looks list|save|rm|path`: the look library (src/formats/looklib.h) from the shell.
// `save` renders the thumbnail headlessly through the public API, as `rouge render` does.
#define _POSIX_C_SOURCE 200809L
#include "app.h"
#include "formats/look.h"
#include "formats/looklib.h"
#include "gl/gl.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

void rs_app_print_looks_help(FILE *f)
{
    fprintf(f,
            "look library (rouge looks):\n"
            "  rouge looks list [--looks DIR]                 the saved looks, newest first: name, date, thumbnail\n"
            "  rouge looks save NAME --look FILE [--force] [--face FACE.rsf] [--no-thumbnail] [--looks DIR]\n"
            "                                                 add a look file under NAME (a name in use is refused\n"
            "                                                 unless --force); the thumbnail is rendered headlessly\n"
            "  rouge looks rm NAME [--looks DIR]              delete a look and its thumbnail\n"
            "  rouge looks path NAME [--looks DIR]            print the look's file (rouge render --look \"$(...)\")\n"
            "  Names: letters, digits, space, - and _, at most %d bytes. The library is $XDG_DATA_HOME/rouge/looks\n"
            "  (else ~/.local/share/rouge/looks) unless --looks names another; the viewer uses the same one.\n",
            RS_LOOKLIB_NAME_MAX);
}

typedef struct looks_args {
    const char *verb, *name, *look, *face, *dir;
    bool force, no_thumb;
} looks_args;

static rs_result parse(int argc, char **argv, looks_args *a, rs_error *err)
{
    memset(a, 0, sizeof *a);
    for (int i = 0; i < argc; i++) {
        const char *s = argv[i];
        const char **value = !strcmp(s, "--look") ? &a->look : !strcmp(s, "--face") ? &a->face
                             : !strcmp(s, "--looks")                                ? &a->dir
                                                                                    : NULL;
        if (value) {
            if (i + 1 >= argc) return rs_fail(err, RS_ERR_ARG, "looks: %s needs a value", s);
            if (*value) return rs_fail(err, RS_ERR_ARG, "looks: %s given twice", s);
            *value = argv[++i];
        } else if (!strcmp(s, "--force")) {
            a->force = true;
        } else if (!strcmp(s, "--no-thumbnail")) {
            a->no_thumb = true;
        } else if (s[0] == '-' && s[1] == '-') {
            return rs_fail(err, RS_ERR_ARG, "looks: unknown option '%s' (see rouge looks --help)", s);
        } else if (!a->verb) {
            a->verb = s;
        } else if (!a->name) {
            a->name = s;
        } else {
            return rs_fail(err, RS_ERR_ARG, "looks: unexpected argument '%s'", s);
        }
    }
    if (!a->verb) return rs_fail(err, RS_ERR_ARG, "looks: say list, save, rm or path (see rouge looks --help)");
    bool named = !strcmp(a->verb, "save") || !strcmp(a->verb, "rm") || !strcmp(a->verb, "path");
    if (!named && strcmp(a->verb, "list"))
        return rs_fail(err, RS_ERR_ARG, "looks: unknown command '%s' (list, save, rm, path)", a->verb);
    if (named && !a->name) return rs_fail(err, RS_ERR_ARG, "looks %s: needs a NAME", a->verb);
    if (!named && a->name) return rs_fail(err, RS_ERR_ARG, "looks list: unexpected argument '%s'", a->name);
    if (!strcmp(a->verb, "save") && !a->look) return rs_fail(err, RS_ERR_ARG, "looks save: needs --look FILE");
    if (strcmp(a->verb, "save") && (a->look || a->face || a->force || a->no_thumb))
        return rs_fail(err, RS_ERR_ARG, "looks %s: --look, --face, --force and --no-thumbnail belong to save", a->verb);
    return a->name ? rs_looklib_check_name(a->name, err) : RS_OK;
}

rouge_view rs_app_thumbnail_view(void)
{
    return (rouge_view){.width = RS_LOOKLIB_THUMB_W, .height = RS_LOOKLIB_THUMB_H, .zoom = RS_APP_THUMB_ZOOM,
                        .pan = {0.0f, RS_APP_THUMB_PAN_Y}};
}

rs_result rs_app_thumbnail(const char *face_path, const void *look, size_t len, rs_image *out, rs_error *err)
{
    rouge_view view = rs_app_thumbnail_view();
    rs_image img = {0};
    rs_result rr = rs_image_create(view.width, view.height, 4, &img, err);
    rs_gl_context *gl = NULL;
    if (!rr) rr = rs_gl_create(&(rs_gl_desc){0}, &gl, err);
    if (rr) {
        rs_image_free(&img);
        return rr;
    }
    rouge_error e = {0};
    rouge_face *face = NULL;
    char env_dir[600];
    rouge_result r = rouge_face_create(
        &(rouge_face_desc){.path = face_path, .view = &view, .env_dir = rs_app_env_dir(env_dir, sizeof env_dir)}, &face,
        &e);
    if (!r) r = rouge_face_load_look_memory(face, look, len, &e);
    if (!r) r = rouge_face_render(face, &e);
    if (!r) r = rouge_face_read_rgba(face, img.pixels, (size_t)img.width * img.height * 4, &e);
    rouge_face_destroy(face);
    rs_gl_destroy(gl);
    if (r) {
        rs_image_free(&img);
        return rs_app_error(r, &e, err);
    }
    // RGBA rows top-first to RGB: a thumbnail has no alpha.
    uint8_t *d = img.pixels;
    for (size_t i = 0; i < (size_t)img.width * img.height; i++, d += 3) memmove(d, img.pixels + i * 4, 3);
    img.channels = 3;
    *out = img;
    return RS_OK;
}

rs_result rs_app_looks(int argc, char **argv, rs_error *err)
{
    looks_args a;
    rs_result r = parse(argc, argv, &a, err);
    if (r != RS_OK) return r;
    char dir[1024];
    // A longer path is refused, not cut (it would name another folder).
    if (a.dir && strlen(a.dir) >= sizeof dir)
        return rs_fail(err, RS_ERR_ARG, "--looks: the path is %zu bytes, at most %zu allowed", strlen(a.dir), sizeof dir - 1);
    if (a.dir) snprintf(dir, sizeof dir, "%s", a.dir);
    else if ((r = rs_looklib_default_dir(dir, sizeof dir, err)) != RS_OK) return r;
    // The folder comes from XDG_DATA_HOME or --looks: printed terminal-safe (no escape sequences).
    char shown[4 * sizeof dir];
    rs_text_sanitize(shown, sizeof shown, dir, strlen(dir));

    if (!strcmp(a.verb, "list")) {
        rs_looklib_entry *e = NULL;
        uint32_t n = 0;
        if ((r = rs_looklib_list(dir, &e, &n, err)) != RS_OK) return r;
        for (uint32_t i = 0; i < n; i++) {
            char when[32] = "?";
            time_t t = (time_t)e[i].mtime_s;
            struct tm tm;
            if (localtime_r(&t, &tm)) strftime(when, sizeof when, "%Y-%m-%d %H:%M", &tm);
            printf("%-*s  %s  %s\n", RS_LOOKLIB_NAME_MAX, e[i].name, when, e[i].has_thumb ? "thumbnail" : "-");
        }
        if (n == 0) fprintf(stderr, "rouge: no looks in %s\n", shown);
        free(e);
        return RS_OK;
    }
    if (!strcmp(a.verb, "path")) {
        char path[1100];
        if ((r = rs_looklib_path(dir, a.name, false, path, sizeof path, err)) != RS_OK) return r;
        if (!rs_looklib_exists(dir, a.name)) return rs_fail(err, RS_ERR_ARG, "no look named '%s' in %s", a.name, dir);
        // Raw for a script that reads it ($(rouge looks path X)), terminal-safe on a terminal.
        char safe[4 * sizeof path];
        rs_text_sanitize(safe, sizeof safe, path, strlen(path));
        printf("%s\n", isatty(STDOUT_FILENO) ? safe : path);
        return RS_OK;
    }
    if (!strcmp(a.verb, "rm")) {
        if ((r = rs_looklib_remove(dir, a.name, err)) != RS_OK) return r;
        printf("rouge: removed look '%s'\n", a.name);
        return RS_OK;
    }
    // save: the file must be a look (parsed here, so a typo'd path or a PNG never enters the library).
    if (!a.force && rs_looklib_exists(dir, a.name))
        return rs_fail(err, RS_ERR_ARG, "a look named '%s' is already in the library (--force replaces it)", a.name);
    void *data = NULL;
    size_t len = 0;
    if ((r = rs_file_read_all(a.look, RS_LOOK_MAX_BYTES, &data, &len, err)) != RS_OK) return r;
    rs_look *look = NULL;
    rs_error inner = {0};
    if ((r = rs_look_parse(data, len, &look, &inner)) != RS_OK) {
        free(data);
        return rs_fail(err, r, "%s: %s", a.look, inner.msg);
    }
    rs_look_destroy(look);
    rs_image thumb = {0};
    char def[600];
    if (!a.no_thumb) r = rs_app_thumbnail(a.face ? a.face : rs_app_default_face(def, sizeof def), data, len, &thumb, err);
    if (r == RS_OK) r = rs_looklib_save(dir, a.name, data, len, a.no_thumb ? NULL : &thumb, a.force, err);
    if (r == RS_OK) printf("rouge: saved look '%s' in %s\n", a.name, shown);
    free(data);
    rs_image_free(&thumb);
    return r;
}
