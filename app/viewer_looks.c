// viewer_looks.c — the viewer's look library (issue 15): a sheet of saved looks with thumbnails (tap to
// load, compare in the split view, delete with a second tap), the save dialog (a name, no silent
// overwrite), and the split's compared look. Storage is src/formats/looklib.h; the sheet's layout is a
// pure function (vw_looks_layout) so tests and scripts can find its buttons.
#define _POSIX_C_SOURCE 200809L
#include "app.h"
#include "viewer_internal.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define ID_BASE 5000  // widget ids of the sheet and dialog: 5000 + ...

// --- layout ---------------------------------------------------------------------------------------------

void vw_looks_layout(int fb_w, int fb_h, float s, vw_looks_sheet_layout *out)
{
    memset(out, 0, sizeof *out);
    float W = (float)fb_w, H = (float)fb_h, m = 12 * s, pad = 16 * s, t = 44 * s, gap = 16 * s;
    out->sheet = (rs_ui_rect){m, m, W - 2 * m, H - 2 * m};
    rs_ui_rect in = rs_ui_rect_inset(out->sheet, pad);
    // Title row: "Looks", then (right-aligned) Save current look, Compare with bare, close.
    out->close = (rs_ui_rect){in.x + in.w - t, in.y, t, t};
    out->bare = (rs_ui_rect){out->close.x - 8 * s - 200 * s, in.y, 200 * s, t};
    out->save = (rs_ui_rect){out->bare.x - 8 * s - 200 * s, in.y, 200 * s, t};
    out->title = (rs_ui_rect){in.x, in.y, RS_MAX(0.0f, out->save.x - in.x), t};
    // Footer: the folder on the left, page buttons on the right.
    out->next = (rs_ui_rect){in.x + in.w - 120 * s, in.y + in.h - t, 120 * s, t};
    out->prev = (rs_ui_rect){out->next.x - 8 * s - 120 * s, out->next.y, 120 * s, t};
    out->folder = (rs_ui_rect){in.x, out->next.y, RS_MAX(0.0f, out->prev.x - in.x - 8 * s), t};
    // The grid of cards: thumbnails at their stored size (times the UI scale) with the name below.
    float tw = RS_LOOKLIB_THUMB_W * s, th = RS_LOOKLIB_THUMB_H * s, name_h = 22 * s;
    float gy0 = in.y + t + gap, gy1 = out->next.y - gap;
    int cols = (int)floorf((in.w + gap) / (tw + gap)), rows = (int)floorf((gy1 - gy0 + gap) / (th + name_h + gap));
    cols = RS_CLAMP(cols, 1, 8), rows = RS_CLAMP(rows, 1, 8);
    while (cols * rows > VW_LOOKS_PAGE_MAX) rows--;
    out->cols = cols, out->rows = rows, out->per_page = cols * rows;
    float x0 = in.x + (in.w - ((float)cols * tw + (float)(cols - 1) * gap)) * 0.5f;
    for (int i = 0; i < out->per_page; i++) {
        int c = i % cols, r = i / cols;
        out->card[i] = (rs_ui_rect){floorf(x0 + (float)c * (tw + gap)), floorf(gy0 + (float)r * (th + name_h + gap)), tw, th};
    }
    // The save dialog, centred.
    float dw = RS_MIN(460 * s, W - 2 * m), dh = 230 * s;
    out->dialog = (rs_ui_rect){floorf((W - dw) * 0.5f), floorf((H - dh) * 0.5f), dw, dh};
    rs_ui_rect di = rs_ui_rect_inset(out->dialog, pad);
    out->field = (rs_ui_rect){di.x, di.y + 40 * s, di.w, t};
    out->cancel = (rs_ui_rect){di.x + di.w - 140 * s, di.y + di.h - t, 140 * s, t};
    out->ok = (rs_ui_rect){out->cancel.x - 8 * s - 160 * s, out->cancel.y, 160 * s, t};
}

// The two icon buttons on a card's thumbnail (top right): compare, delete.
static rs_ui_rect card_button(rs_ui_rect card, int k, float s)
{
    float b = 40 * s;
    return (rs_ui_rect){card.x + card.w - (float)(2 - k) * (b + 4 * s), card.y + 4 * s, b, b};
}

// --- state ----------------------------------------------------------------------------------------------

void vw_looks_init(vw_viewer *v)
{
    vw_looks *L = &v->looks;
    L->confirm_delete = -1;
    L->thumb_page = -1;
    rs_error err = {0};
    if (v->cli->looks) snprintf(L->dir, sizeof L->dir, "%s", v->cli->looks);
    else if (rs_looklib_default_dir(L->dir, sizeof L->dir, &err) != RS_OK) L->dir[0] = 0, vw_toast(v, true, "%s", err.msg);
}

static void drop_thumbs(vw_looks *L)
{
    for (int i = 0; i < VW_LOOKS_PAGE_MAX; i++) rs_ui_texture_free(&L->thumb[i]);
    L->thumb_page = -1;
}

void vw_looks_free(vw_viewer *v)
{
    vw_looks *L = &v->looks;
    drop_thumbs(L);
    free(L->entries);
    L->entries = NULL, L->count = 0;
}

// Re-reads the library (after a save or delete, or when the sheet opens).
static void refresh(vw_viewer *v)
{
    vw_looks *L = &v->looks;
    free(L->entries);
    L->entries = NULL, L->count = 0;
    drop_thumbs(L);
    rs_error err = {0};
    if (L->dir[0] && rs_looklib_list(L->dir, &L->entries, &L->count, &err) != RS_OK) vw_toast(v, true, "%s", err.msg);
    L->selected = RS_CLAMP(L->selected, 0, RS_MAX((int)L->count - 1, 0));
    L->confirm_delete = -1;
}

bool vw_looks_modal(const vw_viewer *v) { return v->looks.open || v->looks.saving; }

void vw_looks_open(vw_viewer *v)
{
    refresh(v);
    v->looks.open = true;
    v->looks.page = 0;
    v->looks.selected = 0;
}

static void close_all(vw_viewer *v)
{
    v->looks.open = v->looks.saving = v->looks.clash = false;
}

void vw_looks_begin_save(vw_viewer *v)
{
    vw_looks *L = &v->looks;
    L->back_to_sheet = L->open;
    L->open = false;
    L->saving = true;
    L->clash = false;
    // A free default name, so a touch screen without a keyboard can save with one tap.
    for (int i = 1; i < 10000; i++) {
        snprintf(L->name, sizeof L->name, "Look %d", i);
        if (!L->dir[0] || !rs_looklib_exists(L->dir, L->name)) break;
    }
}

static void end_save(vw_viewer *v)
{
    vw_looks *L = &v->looks;
    L->saving = L->clash = L->exporting = false;
    if (L->back_to_sheet) vw_looks_open(v);
}

// --- export (S): the picture and its look, where the person says ----------------------------------------

// The export as typed, ending in .png (added when missing), and its look beside it (.look).
static void export_paths(const char *typed, char *png, size_t png_n, char *look, size_t look_n)
{
    size_t n = strlen(typed);
    bool ext = n >= 4 && !strcmp(typed + n - 4, ".png");
    snprintf(png, png_n, "%s%s", typed, ext ? "" : ".png");
    snprintf(look, look_n, "%.*s.look", (int)(ext ? n - 4 : n), typed);
}

// The folder of `path` exists (the export can be written there).
static bool export_dir_ok(const char *path)
{
    char dir[1024];
    snprintf(dir, sizeof dir, "%s", path);
    char *slash = strrchr(dir, '/');
    if (!slash) return true;
    if (slash == dir) slash[1] = 0;
    else *slash = 0;
    struct stat st;
    return stat(dir, &st) == 0 && S_ISDIR(st.st_mode);
}

void vw_looks_begin_export(vw_viewer *v)
{
    vw_looks *L = &v->looks;
    // Prefilled with a free name where the last export went, else in the working directory, as an
    // absolute path: the person sees where before saying yes, and can type another.
    char dir[1024] = ".";
    if (L->export_path[0] && strrchr(L->export_path, '/')) {
        snprintf(dir, sizeof dir, "%s", L->export_path);
        *strrchr(dir, '/') = 0;
    } else if (!getcwd(dir, sizeof dir)) {
        snprintf(dir, sizeof dir, ".");
    }
    char png[1100], look[1100];
    for (int i = 1; i < 10000; i++) {
        snprintf(L->export_path, sizeof L->export_path, "%s/rouge-%04d.png", dir, i);
        export_paths(L->export_path, png, sizeof png, look, sizeof look);
        if (access(png, F_OK) != 0 && access(look, F_OK) != 0) break;
    }
    L->back_to_sheet = L->open;
    L->open = false;
    L->saving = L->exporting = true;
    L->clash = false;
}

// Enter or Export: the dialog closes at once; the file is written when the picture is at full quality.
static void accept_export(vw_viewer *v)
{
    vw_looks *L = &v->looks;
    char png[1100], look[1100];
    export_paths(L->export_path, png, sizeof png, look, sizeof look);
    snprintf(L->export_path, sizeof L->export_path, "%s", png);
    L->export_pending = true;
    end_save(v);
}

void vw_looks_export(vw_viewer *v)
{
    vw_looks *L = &v->looks;
    L->export_pending = false;
    char png[1100], look[1100];
    export_paths(L->export_path, png, sizeof png, look, sizeof look);
    // The current look at full quality, without the split or the UI: the face's view (its last frame's)
    // drawn at twice the size and averaged down (rs_app_render_supersampled: every pixel four samples,
    // highlights included), then the view set back and drawn again. A window
    // past 16 megapixels supersampled (4K and up: a software GL keeps its targets in CPU memory) exports
    // the frame on screen as it is.
    rouge_view keep = rouge_face_get_view(v->face);
    rouge_error e = {0};
    rs_error err = {0};
    rs_image img = {0};
    rs_result r;
    if ((double)keep.width * keep.height * 4.0 <= 16.8e6) {
        r = rs_app_render_supersampled(v->face, 2, &img, &err);
        // The face's frame is what strokes pick in and what the screen shows: drawn again at once.
        rs_result back = rs_app_error(rouge_face_set_view(v->face, &keep, &e), &e, r ? NULL : &err);
        if (!back) back = rs_app_error(rouge_face_render(v->face, &e), &e, r ? NULL : &err);
        if (!r) r = back;
        if (!r) r = rs_image_write_png(png, &img, &err);
        rs_image_free(&img);
    } else {
        r = rs_app_error(rouge_face_write_png(v->face, png, &e), &e, &err);
    }
    if (!r) r = rs_app_error(rouge_face_save_look(v->face, look, &e), &e, &err);
    if (r) {
        vw_toast(v, true, "%s", err.msg);
        return;
    }
    const char *base = strrchr(look, '/');
    vw_toast(v, false, "Exported %s (look: %s)", png, base ? base + 1 : look);
}

// The thumbnail: the face with this look, frontal, framed brows to chin (rs_app_thumbnail_view, as
// `rouge looks save` frames it), in the current lighting. Then the picture on screen must be redrawn (the
// face's last frame is the thumbnail).
static rs_result render_thumbnail(vw_viewer *v, rs_image *out, rs_error *err)
{
    rouge_view tv = v->view, shot = rs_app_thumbnail_view();
    tv.width = shot.width, tv.height = shot.height;
    tv.yaw_deg = tv.pitch_deg = 0;
    tv.zoom = shot.zoom;
    tv.pan[0] = shot.pan[0], tv.pan[1] = shot.pan[1];
    tv.max_splats = 0;
    tv.hide_makeup = tv.compare_look = false;
    tv.mode = ROUGE_MODE_FULL;
    tv.env = v->env_name;
    rouge_error e = {0};
    rs_image img = {0};
    rs_result r = rs_app_error(rouge_face_set_view(v->face, &tv, &e), &e, err);
    if (!r) r = rs_app_error(rouge_face_render(v->face, &e), &e, err);
    if (!r) r = rs_image_create(tv.width, tv.height, 4, &img, err);
    if (!r) r = rs_app_error(rouge_face_read_rgba(v->face, img.pixels, (size_t)img.width * img.height * 4, &e), &e, err);
    v->dirty_view = true;
    v->looks.compare_dirty = true;
    if (r) {
        rs_image_free(&img);
        return r;
    }
    uint8_t *d = img.pixels;
    for (size_t i = 0; i < (size_t)img.width * img.height; i++, d += 3) memmove(d, img.pixels + i * 4, 3);
    img.channels = 3;
    *out = img;
    return RS_OK;
}

static void save(vw_viewer *v, bool overwrite)
{
    vw_looks *L = &v->looks;
    rs_error err = {0};
    if (rs_looklib_check_name(L->name, &err) != RS_OK) {
        vw_toast(v, true, "%s", err.msg);
        return;
    }
    if (!overwrite && rs_looklib_exists(L->dir, L->name)) {
        L->clash = true;  // ask: the dialog offers Overwrite
        return;
    }
    char *text = NULL;
    size_t len = 0;
    rs_image thumb = {0};
    rouge_error e = {0};
    rs_result r = rs_app_error(rouge_face_save_look_memory(v->face, &text, &len, &e), &e, &err);
    if (!r) r = render_thumbnail(v, &thumb, &err);
    if (!r) r = rs_looklib_save(L->dir, L->name, text, len, &thumb, overwrite, &err);
    rouge_free(text);
    rs_image_free(&thumb);
    if (r == RS_ERR_ARG && !overwrite && rs_looklib_exists(L->dir, L->name)) {
        L->clash = true;  // another viewer saved this name meanwhile
        return;
    }
    if (r) {
        vw_toast(v, true, "%s", err.msg);
        return;
    }
    vw_toast(v, false, "Saved look '%s'", L->name);
    end_save(v);
}

static void load(vw_viewer *v, int i)
{
    vw_looks *L = &v->looks;
    if (i < 0 || (uint32_t)i >= L->count) return;
    char path[1100];
    rs_error err = {0};
    if (rs_looklib_path(L->dir, L->entries[i].name, false, path, sizeof path, &err) == RS_OK &&
        vw_load_look_file(v, path, &err) == RS_OK) {
        vw_toast(v, false, "Loaded look '%s'", L->entries[i].name);
        close_all(v);
    }
}

// The split view's left half shows look i (-1: the bare face).
static void compare(vw_viewer *v, int i)
{
    vw_looks *L = &v->looks;
    rs_error err = {0};
    if (i < 0) {
        vw_looks_compare_bare(v);
    } else {
        char path[1100];
        rs_result r = rs_looklib_path(L->dir, L->entries[i].name, false, path, sizeof path, &err);
        rouge_error e = {0};
        if (!r) r = rs_app_error(rouge_face_set_compare_look(v->face, path, &e), &e, &err);
        if (r) {
            vw_toast(v, true, "%s", err.msg);
            return;
        }
        snprintf(L->compare, sizeof L->compare, "%s", L->entries[i].name);
    }
    L->compare_dirty = true;
    v->split = true;
    v->dirty_view = true;
    vw_toast(v, false, "Left: %s, right: the current look (B closes)", L->compare[0] ? L->compare : "bare face");
    close_all(v);
}

static void delete_at(vw_viewer *v, int i)
{
    vw_looks *L = &v->looks;
    if (i < 0 || (uint32_t)i >= L->count) return;
    // The first tap asks, the second deletes.
    if (L->confirm_delete != i) {
        L->confirm_delete = i;
        return;
    }
    rs_error err = {0};
    char name[RS_LOOKLIB_NAME_MAX + 1];
    snprintf(name, sizeof name, "%s", L->entries[i].name);
    if (rs_looklib_remove(L->dir, name, &err) != RS_OK) vw_toast(v, true, "%s", err.msg);
    else vw_toast(v, false, "Deleted look '%s'", name);
    if (!strcmp(name, L->compare)) {
        // Its file is gone: the left half shows the bare face again.
        L->compare[0] = 0, L->compare_dirty = true, v->dirty_view = true;
        rouge_face_set_compare_look(v->face, NULL, NULL);
    }
    refresh(v);
}

void vw_looks_compare_bare(vw_viewer *v)
{
    v->looks.compare[0] = 0;
    v->looks.compare_dirty = true;
    if (v->face) rouge_face_set_compare_look(v->face, NULL, NULL);
}

void vw_looks_forget_face(vw_viewer *v)
{
    // Another face: the compared look was loaded into the old one.
    v->looks.compare[0] = 0;
}

// --- keys and typing ---------------------------------------------------------------------------------------

bool vw_looks_key(vw_viewer *v, int key, int mods)
{
    vw_looks *L = &v->looks;
    if (L->exporting) {
        size_t n = strlen(L->export_path);
        if (key == GLFW_KEY_ESCAPE) end_save(v);
        else if (key == GLFW_KEY_BACKSPACE && n) L->export_path[n - 1] = 0, L->clash = false;
        else if ((key == GLFW_KEY_ENTER || key == GLFW_KEY_KP_ENTER) && !L->clash && n) accept_export(v);
        return true;
    }
    if (L->saving) {
        // The dialog owns the keyboard: letters arrive as characters (vw_looks_char).
        size_t n = strlen(L->name);
        if (key == GLFW_KEY_ESCAPE) end_save(v);
        else if (key == GLFW_KEY_BACKSPACE && n) L->name[n - 1] = 0, L->clash = false;
        else if ((key == GLFW_KEY_ENTER || key == GLFW_KEY_KP_ENTER) && !L->clash) save(v, false);
        return true;
    }
    if (!L->open) return false;
    int per_page = RS_MAX(L->per_page, 1), n = (int)L->count;
    switch (key) {
    case GLFW_KEY_ESCAPE: close_all(v); break;
    case GLFW_KEY_LEFT: L->selected = RS_MAX(L->selected - 1, 0); break;
    case GLFW_KEY_RIGHT: L->selected = RS_MIN(L->selected + 1, RS_MAX(n - 1, 0)); break;
    case GLFW_KEY_UP: L->selected = RS_MAX(L->selected - L->cols, 0); break;
    case GLFW_KEY_DOWN: L->selected = RS_MIN(L->selected + L->cols, RS_MAX(n - 1, 0)); break;
    case GLFW_KEY_ENTER:
    case GLFW_KEY_KP_ENTER: load(v, L->selected); break;
    case GLFW_KEY_C: if (n) compare(v, L->selected); break;
    case GLFW_KEY_B: compare(v, -1); break;
    case GLFW_KEY_DELETE: delete_at(v, L->selected); break;
    case GLFW_KEY_S: if (mods & GLFW_MOD_CONTROL) vw_looks_begin_save(v); break;
    default: break;
    }
    if (n) L->page = L->selected / per_page;
    return true;  // the sheet is modal: no shortcut reaches the face behind it
}

void vw_looks_char(vw_viewer *v, unsigned codepoint)
{
    vw_looks *L = &v->looks;
    if (L->exporting) {
        // A path: any printable character.
        size_t n = strlen(L->export_path);
        if (codepoint >= 32 && codepoint < 127 && n + 1 < sizeof L->export_path)
            L->export_path[n] = (char)codepoint, L->export_path[n + 1] = 0, L->clash = false;
        return;
    }
    if (!L->saving) return;
    size_t n = strlen(L->name);
    char c = codepoint < 128 ? (char)codepoint : 0;
    bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == ' ' || c == '-' ||
              c == '_';
    // Characters a name cannot hold are not typed at all (the rules show under the field).
    if (ok && n < RS_LOOKLIB_NAME_MAX) L->name[n] = c, L->name[n + 1] = 0, L->clash = false;
}

// --- drawing (and taps) -------------------------------------------------------------------------------------

static int text_scale(float s) { return RS_MAX(1, (int)floorf(s * 2 + 0.25f)); }

static void load_page_thumbs(vw_viewer *v)
{
    vw_looks *L = &v->looks;
    if (L->thumb_page == L->page) return;
    drop_thumbs(L);
    L->thumb_page = L->page;
    for (int k = 0; k < L->per_page; k++) {
        int i = L->page * L->per_page + k;
        if ((uint32_t)i >= L->count || !L->entries[i].has_thumb) continue;
        char path[1100];
        rs_image img = {0};
        rs_error err = {0};
        if (rs_looklib_path(L->dir, L->entries[i].name, true, path, sizeof path, &err) == RS_OK &&
            rs_image_read_png(path, &img, &err) == RS_OK && img.width <= 1024 && img.height <= 1024)
            rs_ui_texture_upload(&L->thumb[k], &img, &err);
        rs_image_free(&img);
    }
}

static void draw_sheet(vw_viewer *v, const vw_looks_sheet_layout *l)
{
    vw_looks *L = &v->looks;
    rs_ui *ui = v->ui;
    float s = v->ui_scale;
    int ts = text_scale(s), ts_small = RS_MAX(1, (int)floorf(s + 0.25f));
    L->per_page = l->per_page, L->cols = l->cols;
    int pages = RS_MAX(1, ((int)L->count + l->per_page - 1) / l->per_page);
    L->page = RS_CLAMP(L->page, 0, pages - 1);
    load_page_thumbs(v);
    rs_ui_panel(ui, l->sheet, 18 * s);
    rs_ui_fill(ui, l->sheet, 18 * s, (rs_ui_rgba){22, 22, 27, 200});
    char title[64];
    snprintf(title, sizeof title, "Looks (%u)", L->count);
    rs_ui_text(ui, l->title.x, l->title.y + (l->title.h - 7.0f * (float)ts) * 0.5f, ts, RS_UI_ACCENT, title);
    if (rs_ui_text_button(ui, ID_BASE + 1, l->save, "Save current", false)) vw_looks_begin_save(v);
    if (rs_ui_text_button(ui, ID_BASE + 2, l->bare, "Compare bare", false)) compare(v, -1);
    if (rs_ui_button(ui, ID_BASE + 3, l->close, RS_UI_ICON_CLOSE, false)) close_all(v);
    if (!L->open) return;  // a button above closed the sheet or opened the dialog
    if (L->count == 0) {
        const char *msg = "No looks saved yet: paint, then Save current (Ctrl+S).";
        float w = rs_ui_text_width(msg, ts);
        rs_ui_text(ui, l->sheet.x + (l->sheet.w - w) * 0.5f, l->sheet.y + l->sheet.h * 0.45f, ts, RS_UI_DIM, msg);
    }
    for (int k = 0; k < l->per_page; k++) {
        int i = L->page * l->per_page + k;
        if ((uint32_t)i >= L->count) break;
        rs_ui_rect c = l->card[k];
        // Buttons first: the first widget under a press takes it, so they win over the card behind them.
        rs_ui_rect cb = card_button(c, 0, s), db = card_button(c, 1, s);
        bool asking = L->confirm_delete == i;
        bool cmp_tap = rs_ui_area(ui, ID_BASE + 100 + 3 * k, cb);
        bool del_tap = rs_ui_area(ui, ID_BASE + 101 + 3 * k, db);
        bool card_tap = rs_ui_area(ui, ID_BASE + 102 + 3 * k, c);
        bool hot = rs_ui_hot(ui, ID_BASE + 102 + 3 * k, c);
        rs_ui_shadow(ui, (rs_ui_rect){c.x, c.y + 2 * s, c.w, c.h}, 8 * s, 10 * s, (rs_ui_rgba){0, 0, 0, 90});
        if (L->thumb[k].tex) {
            static const float uv[4] = {0, 0, 1, 1};
            rs_ui_image(ui, L->thumb[k].tex, c, uv);
        } else {
            rs_ui_fill(ui, c, 8 * s, (rs_ui_rgba){60, 60, 66, 255});
            rs_ui_text(ui, c.x + 8 * s, c.y + c.h * 0.5f - 4 * s, ts_small, RS_UI_DIM, "no thumbnail");
        }
        bool sel = i == L->selected;
        rs_ui_stroke(ui, rs_ui_rect_inset(c, -3 * s), 10 * s, sel ? 2.5f * s : 1.5f * s,
                     sel ? RS_UI_ACCENT : hot ? (rs_ui_rgba){255, 255, 255, 120} : (rs_ui_rgba){255, 255, 255, 30});
        const rs_ui_rect btn[2] = {cb, db};
        const rs_ui_icon icon[2] = {RS_UI_ICON_SPLIT, RS_UI_ICON_TRASH};
        for (int b = 0; b < 2; b++) {
            rs_ui_rgba bg = b == 1 && asking ? (rs_ui_rgba){190, 40, 55, 235} : (rs_ui_rgba){15, 15, 18, 170};
            rs_ui_circle(ui, btn[b].x + btn[b].w * 0.5f, btn[b].y + btn[b].h * 0.5f, btn[b].w * 0.45f, bg);
            float is = btn[b].w * 0.55f;
            rs_ui_icon_draw(ui, icon[b],
                            (rs_ui_rect){btn[b].x + (btn[b].w - is) * 0.5f, btn[b].y + (btn[b].h - is) * 0.5f, is, is},
                            RS_UI_WHITE);
        }
        const char *label = asking ? "Tap again to delete" : L->entries[i].name;
        float lw = rs_ui_text_width(label, ts_small);
        rs_ui_text(ui, c.x + (c.w - RS_MIN(lw, c.w)) * 0.5f, c.y + c.h + 6 * s, ts_small,
                   asking ? (rs_ui_rgba){255, 120, 130, 255} : RS_UI_WHITE, label);
        if (del_tap) {
            L->selected = i;
            delete_at(v, i);
            return;  // the list changed
        }
        if (cmp_tap) {
            compare(v, i);
            return;
        }
        if (card_tap) {
            L->selected = i;
            load(v, i);
            return;
        }
    }
    // Footer: where the looks live, and pages.
    char folder[1200];
    snprintf(folder, sizeof folder, "%s", L->dir[0] ? L->dir : "(no folder: --looks DIR)");
    size_t max_chars = (size_t)RS_MAX(8.0f, l->folder.w / (float)(RS_UI_FONT_CELL_W * ts_small));
    if (strlen(folder) > max_chars) {
        size_t cut = strlen(folder) - (max_chars - 3);
        memmove(folder + 3, folder + cut, strlen(folder + cut) + 1);
        memcpy(folder, "...", 3);
    }
    rs_ui_text(ui, l->folder.x, l->folder.y + (l->folder.h - 9.0f * (float)ts_small) * 0.5f, ts_small, RS_UI_DIM,
               folder);
    if (pages > 1) {
        if (rs_ui_text_button(ui, ID_BASE + 4, l->prev, "< Prev", false) && L->page > 0) L->page--;
        if (rs_ui_text_button(ui, ID_BASE + 5, l->next, "Next >", false) && L->page + 1 < pages) L->page++;
    }
    // Taps on the sheet's empty parts cancel a pending delete.
    if (rs_ui_area(ui, ID_BASE + 6, l->sheet)) L->confirm_delete = -1;
}

static void draw_dialog(vw_viewer *v, const vw_looks_sheet_layout *l)
{
    vw_looks *L = &v->looks;
    rs_ui *ui = v->ui;
    float s = v->ui_scale;
    int ts = text_scale(s), ts_small = RS_MAX(1, (int)floorf(s + 0.25f));
    rs_ui_rect d = l->dialog;
    rs_ui_panel(ui, d, 18 * s);
    rs_ui_fill(ui, d, 18 * s, (rs_ui_rgba){22, 22, 27, 220});
    rs_ui_rect in = rs_ui_rect_inset(d, 16 * s);
    rs_ui_text(ui, in.x, in.y + 6 * s, ts, RS_UI_ACCENT, L->exporting ? "Export picture as" : "Save look as");
    // What is typed, and said while typing: a name or file in use turns Save into Overwrite (Enter never
    // overwrites).
    char note[1300], shown[1100];
    rs_ui_rgba note_c = RS_UI_DIM, bad_c = {255, 130, 140, 255};
    bool valid;
    if (L->exporting) {
        char png[1100], look[1100];
        export_paths(L->export_path, png, sizeof png, look, sizeof look);
        valid = L->export_path[0] && export_dir_ok(png);
        L->clash = valid && access(png, F_OK) == 0;
        const char *base = strrchr(look, '/');
        if (L->clash) snprintf(note, sizeof note, "That file exists: Overwrite replaces it"), note_c = bad_c;
        else if (!valid) snprintf(note, sizeof note, "No such folder"), note_c = bad_c;
        else snprintf(note, sizeof note, "The current look at full quality; its look beside it: %s", base ? base + 1 : look);
        // A long path shows its end (the file name), where typing happens.
        size_t fit = (size_t)RS_MAX(8.0f, (l->field.w - 30 * s) / (float)(RS_UI_FONT_CELL_W * ts)), n = strlen(L->export_path);
        snprintf(shown, sizeof shown, "%s%s", n > fit ? "..." : "", L->export_path + (n > fit ? n - fit + 3 : 0));
    } else {
        rs_error err = {0};
        valid = rs_looklib_check_name(L->name, &err) == RS_OK;
        L->clash = valid && L->dir[0] && rs_looklib_exists(L->dir, L->name);
        if (L->clash) snprintf(note, sizeof note, "'%s' is already in the library: Overwrite replaces it", L->name), note_c = bad_c;
        else if (!valid) snprintf(note, sizeof note, "%s", err.msg), note_c = bad_c;
        else snprintf(note, sizeof note, "Letters, digits, space, - and _ (up to %d)", RS_LOOKLIB_NAME_MAX);
        snprintf(shown, sizeof shown, "%s", L->name);
    }
    // The field, with a caret blinking at its end.
    rs_ui_fill(ui, l->field, 10 * s, (rs_ui_rgba){8, 8, 10, 255});
    rs_ui_stroke(ui, l->field, 10 * s, 1.5f * s, L->clash ? (rs_ui_rgba){230, 80, 95, 255} : RS_UI_ACCENT);
    float tx = l->field.x + 12 * s, ty = l->field.y + (l->field.h - 7.0f * (float)ts) * 0.5f;
    float w = rs_ui_text(ui, tx, ty, ts, RS_UI_WHITE, shown);
    if (fmod(vw_now(), 1.0) < 0.6) rs_ui_fill(ui, (rs_ui_rect){tx + w + 3 * s, ty - 2 * s, 2 * s, 11.0f * (float)ts}, 0, RS_UI_WHITE);
    rs_ui_text(ui, l->field.x, l->field.y + l->field.h + 10 * s, ts_small, note_c, note);
    const char *ok = L->clash ? "Overwrite" : L->exporting ? "Export" : "Save";
    if (rs_ui_text_button(ui, ID_BASE + 20, l->ok, ok, valid) && valid) {
        if (L->exporting) accept_export(v);
        else save(v, L->clash);
    }
    if (L->saving && rs_ui_text_button(ui, ID_BASE + 21, l->cancel, "Cancel", false)) end_save(v);
}

void vw_looks_draw(vw_viewer *v)
{
    if (!vw_looks_modal(v)) return;
    vw_looks_sheet_layout l;
    vw_looks_layout(v->fb_w, v->fb_h, v->ui_scale, &l);
    rs_ui_fill(v->ui, (rs_ui_rect){0, 0, (float)v->fb_w, (float)v->fb_h}, 0, (rs_ui_rgba){0, 0, 0, 120});
    if (v->looks.saving) draw_dialog(v, &l);
    else draw_sheet(v, &l);
    // Modal: presses anywhere else belong to the sheet (and do nothing), not to the face behind it.
    rs_ui_area(v->ui, ID_BASE + 7, (rs_ui_rect){0, 0, (float)v->fb_w, (float)v->fb_h});
}

bool vw_looks_comparing(const vw_viewer *v) { return v->looks.compare[0] != 0; }
