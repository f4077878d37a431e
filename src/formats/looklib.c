// looklib.c — the look library (looklib.h): a directory of NAME.look + NAME.png.
#define _POSIX_C_SOURCE 200809L  // link, fsync, lstat
#include "formats/looklib.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

rs_result rs_looklib_default_dir(char *out, size_t cap, rs_error *err)
{
    // XDG Base Directory: $XDG_DATA_HOME if set and absolute, else ~/.local/share.
    const char *xdg = getenv("XDG_DATA_HOME"), *home = getenv("HOME");
    int n;
    if (xdg && xdg[0] == '/') n = snprintf(out, cap, "%s/rouge/looks", xdg);
    else if (home && home[0] == '/') n = snprintf(out, cap, "%s/.local/share/rouge/looks", home);
    else return rs_fail(err, RS_ERR_ARG, "looks: neither XDG_DATA_HOME nor HOME is set: name a folder with --looks");
    if (n < 0 || (size_t)n >= cap) return rs_fail(err, RS_ERR_ARG, "looks: the library's path is too long");
    return RS_OK;
}

rs_result rs_looklib_check_name(const char *name, rs_error *err)
{
    size_t n = strlen(name);
    if (n == 0) return rs_fail(err, RS_ERR_ARG, "look name: empty");
    if (n > RS_LOOKLIB_NAME_MAX)
        return rs_fail(err, RS_ERR_ARG, "look name: %zu bytes, at most %d", n, RS_LOOKLIB_NAME_MAX);
    for (size_t i = 0; i < n; i++) {
        unsigned char c = (unsigned char)name[i];
        bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == ' ' ||
                  c == '-' || c == '_';
        if (!ok) {
            // Printable ASCII is quoted as is; anything else (controls, '/', UTF-8) by its byte value.
            if (c > ' ' && c < 127)
                return rs_fail(err, RS_ERR_ARG, "look name: '%c' not allowed (letters, digits, space, - and _)", c);
            return rs_fail(err, RS_ERR_ARG, "look name: byte 0x%02x not allowed (letters, digits, space, - and _)", c);
        }
    }
    if (name[0] == ' ' || name[n - 1] == ' ')
        return rs_fail(err, RS_ERR_ARG, "look name: may not begin or end with a space");
    if (name[0] == '-') return rs_fail(err, RS_ERR_ARG, "look name: may not begin with '-' (it reads as an option)");
    return RS_OK;
}

static rs_result join(const char *dir, const char *prefix, const char *name, const char *ext, char *out, size_t cap,
                      rs_error *err)
{
    int n = snprintf(out, cap, "%s/%s%s%s", dir, prefix, name, ext);
    if (n < 0 || (size_t)n >= cap) return rs_fail(err, RS_ERR_ARG, "looks: path too long in %s", dir);
    return RS_OK;
}

rs_result rs_looklib_path(const char *dir, const char *name, bool thumb, char *out, size_t cap, rs_error *err)
{
    rs_result r = rs_looklib_check_name(name, err);
    if (r != RS_OK) return r;
    return join(dir, "", name, thumb ? ".png" : ".look", out, cap, err);
}

static bool is_regular(const char *path, int64_t *mtime)
{
    struct stat st;
    if (lstat(path, &st) != 0 || !S_ISREG(st.st_mode)) return false;
    if (mtime) *mtime = (int64_t)st.st_mtime;
    return true;
}

bool rs_looklib_exists(const char *dir, const char *name)
{
    char path[1024];
    return rs_looklib_path(dir, name, false, path, sizeof path, NULL) == RS_OK && is_regular(path, NULL);
}

// mkdir -p, each component 0755.
static rs_result make_dirs(const char *dir, rs_error *err)
{
    char p[1024];
    size_t n = strlen(dir);
    if (n == 0 || n >= sizeof p) return rs_fail(err, RS_ERR_ARG, "looks: bad folder '%s'", dir);
    memcpy(p, dir, n + 1);
    for (size_t i = 1; i <= n; i++) {
        if (p[i] != '/' && p[i] != '\0') continue;
        char c = p[i];
        p[i] = '\0';
        if (mkdir(p, 0755) != 0 && errno != EEXIST)
            return rs_fail(err, RS_ERR_IO, "looks: cannot create %s: %s", p, strerror(errno));
        p[i] = c;
    }
    struct stat st;
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode))
        return rs_fail(err, RS_ERR_IO, "looks: %s is not a folder", dir);
    return RS_OK;
}

rs_result rs_looklib_make_dir(const char *dir, rs_error *err) { return make_dirs(dir, err); }

// The directory's entries (links, renames) reach the disk.
static void sync_dir(const char *dir)
{
    int fd = open(dir, O_RDONLY | O_DIRECTORY);
    if (fd >= 0) {
        fsync(fd);
        close(fd);
    }
}

// Temporaries a saver left when it was killed (.NAME.look.tmp.PID, .NAME.png.tmp.PID whose PID is gone):
// nothing else ever removes them (later saves use their own PID; list and rm never see hidden files).
static void remove_stale_temps(const char *dir, const char *name)
{
    DIR *d = opendir(dir);
    if (!d) return;
    size_t nl = strlen(name);
    struct dirent *de;
    while ((de = readdir(d)) != NULL) {
        const char *f = de->d_name, *rest = f + 1 + nl;
        if (f[0] != '.' || strncmp(f + 1, name, nl) != 0) continue;
        if (!strncmp(rest, ".look.tmp.", 10)) rest += 10;
        else if (!strncmp(rest, ".png.tmp.", 9)) rest += 9;
        else continue;
        char *end;
        long pid = strtol(rest, &end, 10);
        if (end == rest || *end || pid <= 0 || pid == (long)getpid()) continue;
        // A live saver's temporary stays (kill with signal 0 only asks whether the process exists).
        if (kill((pid_t)pid, 0) == 0 || errno != ESRCH) continue;
        char path[1100];
        if (snprintf(path, sizeof path, "%s/%s", dir, f) < (int)sizeof path) unlink(path);
    }
    closedir(d);
}

// A failure writing a temporary names the look, not the hidden file (a full disk said
// ".Evening.look.tmp.812: write failed: No space left on device").
static rs_result name_the_look(rs_result r, const char *tmp, const char *look, rs_error *err)
{
    size_t n = strlen(tmp);
    if (r == RS_OK || !err || strncmp(err->msg, tmp, n) != 0) return r;
    char rest[sizeof err->msg];
    snprintf(rest, sizeof rest, "%s", err->msg + n);
    return rs_fail(err, r, "looks: cannot save %s%s", look, rest);
}

rs_result rs_looklib_save(const char *dir, const char *name, const void *look_text, size_t len,
                          const rs_image *thumb, bool overwrite, rs_error *err)
{
    char look[1024], png[1024], tmp_look[1100], tmp_png[1100], suffix[48];
    rs_result r = rs_looklib_path(dir, name, false, look, sizeof look, err);
    if (r == RS_OK) r = rs_looklib_path(dir, name, true, png, sizeof png, err);
    // Temporaries are hidden (leading '.': never listed) and carry our pid (no other saver uses them).
    snprintf(suffix, sizeof suffix, ".tmp.%ld", (long)getpid());
    char ext[64];
    snprintf(ext, sizeof ext, ".look%s", suffix);
    if (r == RS_OK) r = join(dir, ".", name, ext, tmp_look, sizeof tmp_look, err);
    snprintf(ext, sizeof ext, ".png%s", suffix);
    if (r == RS_OK) r = join(dir, ".", name, ext, tmp_png, sizeof tmp_png, err);
    if (r == RS_OK && !overwrite && is_regular(look, NULL))
        r = rs_fail(err, RS_ERR_ARG, "a look named '%s' is already in the library (overwrite it or pick another name)",
                    name);
    if (r == RS_OK) r = make_dirs(dir, err);
    if (r != RS_OK) return r;
    remove_stale_temps(dir, name);
    r = name_the_look(rs_file_write_atomic(tmp_look, look_text, len, err), tmp_look, look, err);
    if (r == RS_OK && thumb) r = name_the_look(rs_image_write_png(tmp_png, thumb, err), tmp_png, png, err);
    if (r == RS_OK) {
        // Without overwrite the new name is made by link(), which fails if it exists: no check-then-write
        // race with another saver.
        int rc = overwrite ? rename(tmp_look, look) : link(tmp_look, look);
        if (rc != 0 && errno == EEXIST)
            r = rs_fail(err, RS_ERR_ARG, "a look named '%s' is already in the library (overwrite it or pick another "
                        "name)", name);
        else if (rc != 0)
            r = rs_fail(err, RS_ERR_IO, "looks: cannot save %s: %s", look, strerror(errno));
    }
    if (r == RS_OK) {
        // The thumbnail follows its look; a look saved without one loses the old one.
        if (thumb && rename(tmp_png, png) != 0)
            r = rs_fail(err, RS_ERR_IO, "looks: cannot save %s: %s", png, strerror(errno));
        if (!thumb) unlink(png);
    }
    unlink(tmp_look);  // after link() (or a failure); gone already after rename()
    unlink(tmp_png);
    sync_dir(dir);
    return r;
}

static int newest_first(const void *pa, const void *pb)
{
    const rs_looklib_entry *a = pa, *b = pb;
    if (a->mtime_s != b->mtime_s) return a->mtime_s > b->mtime_s ? -1 : 1;
    return strcmp(a->name, b->name);
}

rs_result rs_looklib_list(const char *dir, rs_looklib_entry **out, uint32_t *count, rs_error *err)
{
    *out = NULL;
    *count = 0;
    DIR *d = opendir(dir);
    if (!d) {
        if (errno == ENOENT) return RS_OK;  // nothing saved yet
        return rs_fail(err, RS_ERR_IO, "looks: cannot read %s: %s", dir, strerror(errno));
    }
    rs_looklib_entry *e = NULL;
    uint32_t n = 0, cap = 0;
    rs_result r = RS_OK;
    struct dirent *de;
    while (r == RS_OK && n < RS_LOOKLIB_MAX_LOOKS && (de = readdir(d)) != NULL) {
        size_t len = strlen(de->d_name);
        if (len <= 5 || strcmp(de->d_name + len - 5, ".look") != 0 || len - 5 > RS_LOOKLIB_NAME_MAX) continue;
        rs_looklib_entry it = {0};
        memcpy(it.name, de->d_name, len - 5);
        char path[1024];
        if (rs_looklib_path(dir, it.name, false, path, sizeof path, NULL) != RS_OK || !is_regular(path, &it.mtime_s))
            continue;
        it.has_thumb = rs_looklib_path(dir, it.name, true, path, sizeof path, NULL) == RS_OK && is_regular(path, NULL);
        if (n == cap) {
            uint32_t nc = cap ? cap * 2 : 32;
            rs_looklib_entry *ne = realloc(e, (size_t)nc * sizeof *e);
            if (!ne) {
                r = rs_fail(err, RS_ERR_NOMEM, "looks: out of memory listing %s", dir);
                break;
            }
            e = ne, cap = nc;
        }
        e[n++] = it;
    }
    closedir(d);
    if (r != RS_OK) {
        free(e);
        return r;
    }
    if (n) qsort(e, n, sizeof *e, newest_first);
    *out = e;
    *count = n;
    return RS_OK;
}

rs_result rs_looklib_remove(const char *dir, const char *name, rs_error *err)
{
    char look[1024], png[1024];
    rs_result r = rs_looklib_path(dir, name, false, look, sizeof look, err);
    if (r == RS_OK) r = rs_looklib_path(dir, name, true, png, sizeof png, err);
    if (r != RS_OK) return r;
    remove_stale_temps(dir, name);
    if (!is_regular(look, NULL)) return rs_fail(err, RS_ERR_ARG, "no look named '%s' in %s", name, dir);
    if (unlink(look) != 0) return rs_fail(err, RS_ERR_IO, "looks: cannot remove %s: %s", look, strerror(errno));
    unlink(png);
    sync_dir(dir);
    return RS_OK;
}
