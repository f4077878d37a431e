// looklib.h — the look library: named looks in a directory, each a look file (src/formats/look.h) with a
// thumbnail beside it.
//
// Does: choose the library's directory ($XDG_DATA_HOME/rouge/looks, else ~/.local/share/rouge/looks;
// an app may name another); check a look's name (what may become a file name: letters, digits, space,
// '-' and '_', at most RS_LOOKLIB_NAME_MAX bytes, no leading/trailing space, no '.', '/' or control
// characters); save a look's text and thumbnail under a name, refusing to replace an existing look
// unless told to (the check and the write are one atomic link, so two savers cannot both "win");
// list the looks newest first; give a look's file paths; remove a look.
// Does not: render thumbnails or apply looks (the app renders; rs_look_load applies a look file), or
// keep state: every call works on the directory as it is.
//
//   char dir[512];
//   rs_looklib_default_dir(dir, sizeof dir, &err);
//   if (rs_looklib_save(dir, "Evening", text, len, &thumb, false, &err) != RS_OK) puts(err.msg);  // clash: ERR_ARG
//   rs_looklib_entry *e; uint32_t n;
//   rs_looklib_list(dir, &e, &n, &err);   // then free(e)
#ifndef RS_LOOKLIB_H
#define RS_LOOKLIB_H

#include "core/core.h"
#include "core/image.h"

#define RS_LOOKLIB_NAME_MAX 40      // bytes of a look's name
#define RS_LOOKLIB_MAX_LOOKS 4096   // a listing stops there
#define RS_LOOKLIB_THUMB_W 160      // thumbnails the apps render (pixels); any size is stored as given
#define RS_LOOKLIB_THUMB_H 120

typedef struct rs_looklib_entry {
    char name[RS_LOOKLIB_NAME_MAX + 1];
    int64_t mtime_s;   // last saved, seconds since the epoch
    bool has_thumb;    // NAME.png exists beside NAME.look
} rs_looklib_entry;

// The default library directory (not created here). Fails only when neither XDG_DATA_HOME nor HOME is
// set to an absolute path, or the path does not fit.
rs_result rs_looklib_default_dir(char *out, size_t cap, rs_error *err);

// RS_ERR_ARG with the reason ("name: '.' not allowed (letters, digits, space, - and _)") when `name`
// cannot be a look's name.
rs_result rs_looklib_check_name(const char *name, rs_error *err);
// Creates the library's folder (and its parents) if missing: for files kept beside the looks.
rs_result rs_looklib_make_dir(const char *dir, rs_error *err);

// dir/NAME.look (thumb false) or dir/NAME.png (thumb true), after checking the name.
rs_result rs_looklib_path(const char *dir, const char *name, bool thumb, char *out, size_t cap, rs_error *err);

// Whether a look of that name is in the library.
bool rs_looklib_exists(const char *dir, const char *name);

// Saves look text (rs_look_write_memory) and an optional thumbnail (NULL: none; an old one is removed)
// as `name`, creating the directory if needed. An existing look of that name is replaced only with
// `overwrite`; otherwise RS_ERR_ARG "a look named 'X' is already in the library". Nothing half-written
// is ever visible: both files are written to temporaries and linked/renamed into place.
rs_result rs_looklib_save(const char *dir, const char *name, const void *look_text, size_t len,
                          const rs_image *thumb, bool overwrite, rs_error *err);

// The looks in the library, newest first (*out malloc'd, free it; NULL and 0 when there are none or the
// directory does not exist yet). Files whose names are not look names are not listed.
rs_result rs_looklib_list(const char *dir, rs_looklib_entry **out, uint32_t *count, rs_error *err);

// Removes a look and its thumbnail; RS_ERR_ARG when there is no such look.
rs_result rs_looklib_remove(const char *dir, const char *name, rs_error *err);

#endif
