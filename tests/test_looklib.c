// test_looklib.c — the look library (src/formats/looklib.c): save / list / load / delete, name clashes
// (refused unless overwriting, also when two savers race), bad names, the default folder, thumbnails.
#define _POSIX_C_SOURCE 200809L  // setenv, mkdtemp
#include "support/harness.h"
#include "formats/look.h"
#include "formats/looklib.h"

#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#define REQUIRE(cond) RS_REQUIRE(cond, "%s", #cond)

// A fresh, empty library folder under the test output folder.
static void fresh_dir(const char *tag, char *out, size_t cap)
{
    snprintf(out, cap, "%s/looklib_%s", rs_test_out_dir(), tag);
    char cmd[1200];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", out);
    if (system(cmd) != 0) RS_CHECK(false, "cannot clear %s", out);
}

// A small face (a plane) and a layer with one blush stroke: a real look to store.
static rs_splat_cloud *plane(void)
{
    enum { K = 41 };
    rs_splat s[K * K];
    for (int y = 0; y < K; y++)
        for (int x = 0; x < K; x++)
            s[y * K + x] = (rs_splat){{-0.5f + x / (K - 1.0f), -0.5f + y / (K - 1.0f), 0}, {0, 0, 1}, 1.0f / (K - 1),
                                      {200, 150, 130}, RS_REGION_CHEEK};
    rs_splat_header h;
    memset(&h, 0, sizeof h);
    h.mm_per_unit = 190.0f, h.face_height = 1.0f, h.forward[2] = 1.0f, h.up[1] = 1.0f, h.lod_count = 1;
    h.lods[0] = K * K;
    rs_splat_cloud *c = NULL;
    rs_error err = {0};
    RS_CHECK(rs_splat_create(s, K * K, &h, &c, &err) == RS_OK, "%s", err.msg);
    return c;
}

static char *look_text(rs_makeup *mk, const char *cosmetic, float x, size_t *len)
{
    rs_error err = {0};
    rs_makeup_stamp_desc d = {.pos = {x, 0, 0}, .view_dir = {0, 0, 1}, .radius = 0.1f, .opacity = 0.8f,
                              .pressure = 1.0f, .cosmetic = rs_cosmetic_find(cosmetic)};
    RS_CHECK(rs_makeup_stamp(mk, &d, NULL, &err) == RS_OK, "%s", err.msg);
    char *text = NULL;
    RS_CHECK(rs_look_write_memory(mk, &text, len, &err) == RS_OK, "%s", err.msg);
    return text;
}

static rs_image thumb(uint8_t grey)
{
    rs_image img = {0};
    rs_error err = {0};
    if (rs_image_create(RS_LOOKLIB_THUMB_W, RS_LOOKLIB_THUMB_H, 3, &img, &err) == RS_OK)
        memset(img.pixels, grey, (size_t)img.width * img.height * 3);
    return img;
}

static int files_in(const char *dir)
{
    DIR *d = opendir(dir);
    int n = 0;
    struct dirent *e;
    while (d && (e = readdir(d)) != NULL) n += e->d_name[0] != '.';
    if (d) closedir(d);
    return n;
}

static int hidden_in(const char *dir)
{
    DIR *d = opendir(dir);
    int n = 0;
    struct dirent *e;
    while (d && (e = readdir(d)) != NULL) n += e->d_name[0] == '.' && strcmp(e->d_name, ".") && strcmp(e->d_name, "..");
    if (d) closedir(d);
    return n;
}

static void test_save_list_load_delete(void)
{
    char dir[600];
    fresh_dir("basic", dir, sizeof dir);
    rs_splat_cloud *c = plane();
    rs_makeup *mk = NULL, *back = NULL;
    rs_error err = {0};
    REQUIRE(c && rs_makeup_create(c, NULL, &mk, &err) == RS_OK && rs_makeup_create(c, NULL, &back, &err) == RS_OK);
    // Nothing saved yet: the folder need not exist.
    rs_looklib_entry *e = NULL;
    uint32_t n = 99;
    RS_CHECK(rs_looklib_list(dir, &e, &n, &err) == RS_OK && n == 0 && e == NULL, "empty library: %u", n);
    size_t len;
    char *text = look_text(mk, "blush", -0.2f, &len);
    rs_image th = thumb(90);
    RS_CHECK(rs_looklib_save(dir, "Evening look", text, len, &th, false, &err) == RS_OK, "save: %s", err.msg);
    free(text);
    text = look_text(mk, "bronzer", 0.2f, &len);
    RS_CHECK(rs_looklib_save(dir, "day_2", text, len, NULL, false, &err) == RS_OK, "save: %s", err.msg);
    RS_CHECK(rs_looklib_exists(dir, "Evening look") && rs_looklib_exists(dir, "day_2") &&
                 !rs_looklib_exists(dir, "night"),
             "exists");
    // Both listed, with and without thumbnail; the later save first.
    RS_CHECK(rs_looklib_list(dir, &e, &n, &err) == RS_OK && n == 2, "listed %u: %s", n, err.msg);
    if (n == 2) {
        bool a = strcmp(e[0].name, "day_2") == 0 || e[0].mtime_s == e[1].mtime_s;
        RS_CHECK(a, "newest first: %s, %s", e[0].name, e[1].name);
        for (int i = 0; i < 2; i++)
            RS_CHECK(e[i].has_thumb == (strcmp(e[i].name, "Evening look") == 0), "%s: thumbnail %d", e[i].name,
                     e[i].has_thumb);
    }
    free(e);
    // Load: the saved text replays to the layer it was written from.
    char path[1024];
    REQUIRE(rs_looklib_path(dir, "day_2", false, path, sizeof path, &err) == RS_OK);
    RS_CHECK(rs_look_load(back, path, NULL, &err) == RS_OK, "load: %s", err.msg);
    RS_CHECK(memcmp(rs_makeup_records(back), rs_makeup_records(mk), rs_makeup_count(mk) * sizeof(rs_makeup_gpu)) == 0,
             "loaded look differs from the saved layer");
    rs_image png = {0};
    REQUIRE(rs_looklib_path(dir, "Evening look", true, path, sizeof path, &err) == RS_OK);
    RS_CHECK(rs_image_read_png(path, &png, &err) == RS_OK && png.width == RS_LOOKLIB_THUMB_W && png.pixels[0] == 90,
             "thumbnail: %s", err.msg);
    rs_image_free(&png);
    // Delete: the look and its thumbnail go; deleting again or a look never saved is an error.
    RS_CHECK(rs_looklib_remove(dir, "Evening look", &err) == RS_OK, "remove: %s", err.msg);
    RS_CHECK(!rs_looklib_exists(dir, "Evening look") && files_in(dir) == 1, "%d files left", files_in(dir));
    RS_CHECK(rs_looklib_remove(dir, "Evening look", &err) == RS_ERR_ARG && strstr(err.msg, "no look named"), "%s",
             err.msg);
    RS_CHECK(rs_looklib_list(dir, &e, &n, &err) == RS_OK && n == 1 && strcmp(e[0].name, "day_2") == 0, "after rm");
    free(e);
    RS_CHECK(hidden_in(dir) == 0, "temporary files left in the library");
    free(text);
    rs_image_free(&th);
    rs_makeup_destroy(mk);
    rs_makeup_destroy(back);
    rs_splat_destroy(c);
}

static void test_name_clash_is_refused_unless_overwriting(void)
{
    char dir[600], path[1024];
    fresh_dir("clash", dir, sizeof dir);
    rs_error err = {0};
    rs_image a = thumb(10), b = thumb(200);
    REQUIRE(rs_looklib_save(dir, "mine", "rouge-look 1\nface height=1\n", 28, &a, false, &err) == RS_OK);
    // The same name again: refused, the first look and its thumbnail untouched.
    RS_CHECK(rs_looklib_save(dir, "mine", "rouge-look 1\nface height=2\n", 28, &b, false, &err) == RS_ERR_ARG &&
                 strstr(err.msg, "already in the library"),
             "clash: %s", err.msg);
    void *data = NULL;
    size_t len = 0;
    REQUIRE(rs_looklib_path(dir, "mine", false, path, sizeof path, &err) == RS_OK);
    RS_CHECK(rs_file_read_all(path, 1024, &data, &len, &err) == RS_OK && len == 28 && strstr(data, "height=1"),
             "the clash replaced the look");
    free(data);
    rs_image png = {0};
    REQUIRE(rs_looklib_path(dir, "mine", true, path, sizeof path, &err) == RS_OK);
    RS_CHECK(rs_image_read_png(path, &png, &err) == RS_OK && png.pixels[0] == 10, "the clash replaced the thumbnail");
    rs_image_free(&png);
    // Names differ by case only: two looks (file systems here are case-sensitive).
    RS_CHECK(rs_looklib_save(dir, "Mine", "x", 1, NULL, false, &err) == RS_OK, "%s", err.msg);
    // Overwrite replaces both files.
    RS_CHECK(rs_looklib_save(dir, "mine", "rouge-look 1\nface height=2\n", 28, &b, true, &err) == RS_OK, "%s", err.msg);
    REQUIRE(rs_looklib_path(dir, "mine", false, path, sizeof path, &err) == RS_OK);
    RS_CHECK(rs_file_read_all(path, 1024, &data, &len, &err) == RS_OK && strstr(data, "height=2"), "not overwritten");
    free(data);
    REQUIRE(rs_looklib_path(dir, "mine", true, path, sizeof path, &err) == RS_OK);
    RS_CHECK(rs_image_read_png(path, &png, &err) == RS_OK && png.pixels[0] == 200, "thumbnail not overwritten");
    rs_image_free(&png);
    // Overwriting without a thumbnail drops the old one (it would show another look).
    RS_CHECK(rs_looklib_save(dir, "mine", "y", 1, NULL, true, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(access(path, F_OK) != 0, "stale thumbnail kept");
    // Two processes save the same new name at once: exactly one wins, the other is told it exists.
    int wins = 0, clashes = 0;
    for (int round = 0; round < 10; round++) {
        char name[32];
        snprintf(name, sizeof name, "race %d", round);
        pid_t kids[2];
        for (int k = 0; k < 2; k++) {
            kids[k] = fork();
            if (kids[k] == 0) {
                rs_error e2 = {0};
                rs_result r = rs_looklib_save(dir, name, k ? "second" : "first", k ? 6 : 5, NULL, false, &e2);
                _exit(r == RS_OK ? 0 : r == RS_ERR_ARG ? 3 : 1);
            }
        }
        for (int k = 0; k < 2; k++) {
            int st = 0;
            waitpid(kids[k], &st, 0);
            wins += WIFEXITED(st) && WEXITSTATUS(st) == 0;
            clashes += WIFEXITED(st) && WEXITSTATUS(st) == 3;
        }
    }
    RS_CHECK(wins == 10 && clashes == 10, "10 races: %d saves won, %d refused", wins, clashes);
    RS_CHECK(hidden_in(dir) == 0, "temporary files left in the library");
    rs_image_free(&a);
    rs_image_free(&b);
}

static void test_bad_names_are_refused_with_a_reason(void)
{
    char dir[600];
    fresh_dir("names", dir, sizeof dir);
    static const struct { const char *name, *why; } bad[] = {
        {"", "empty"},
        {"a/b", "'/' not allowed"},
        {"../up", "'.' not allowed"},
        {"look.v2", "'.' not allowed"},
        {".hidden", "'.' not allowed"},
        {"tab\there", "byte 0x09"},
        {"new\nline", "byte 0x0a"},
        {"esc\x1b[2J", "byte 0x1b"},
        {"caf\xc3\xa9", "byte 0xc3"},
        {" lead", "begin or end with a space"},
        {"trail ", "begin or end with a space"},
        {"-rf", "begin with '-'"},
        {"star*", "'*' not allowed"},
        {"12345678901234567890123456789012345678901", "at most 40"},
    };
    rs_error err = {0};
    for (size_t i = 0; i < RS_COUNT_OF(bad); i++) {
        RS_CHECK(rs_looklib_save(dir, bad[i].name, "x", 1, NULL, false, &err) == RS_ERR_ARG, "'%s' saved", bad[i].name);
        RS_CHECK(strstr(err.msg, bad[i].why) != NULL, "'%s': message '%s' lacks '%s'", bad[i].name, err.msg, bad[i].why);
        RS_CHECK(!rs_looklib_exists(dir, bad[i].name), "'%s' exists", bad[i].name);
    }
    RS_CHECK(files_in(dir) == 0, "bad names left %d files", files_in(dir));
    static const char *const good[] = {"a", "Look 1", "evening_smoky-eye", "1234567890123456789012345678901234567890"};
    for (size_t i = 0; i < RS_COUNT_OF(good); i++)
        RS_CHECK(rs_looklib_check_name(good[i], &err) == RS_OK, "'%s' refused: %s", good[i], err.msg);
    // Files in the folder that are not looks (or not look names) are not listed.
    mkdir(dir, 0755);
    char path[1024];
    snprintf(path, sizeof path, "%s/notes.txt", dir);
    REQUIRE(rs_file_write_atomic(path, "x", 1, &err) == RS_OK);
    snprintf(path, sizeof path, "%s/bad.name.look", dir);
    REQUIRE(rs_file_write_atomic(path, "x", 1, &err) == RS_OK);
    snprintf(path, sizeof path, "%s/sub.look", dir);
    mkdir(path, 0755);
    rs_looklib_entry *e = NULL;
    uint32_t n = 0;
    RS_CHECK(rs_looklib_list(dir, &e, &n, &err) == RS_OK && n == 0, "listed %u non-looks", n);
    free(e);
}

static void test_default_folder_follows_xdg(void)
{
    char out[600];
    rs_error err = {0};
    const char *old_xdg = getenv("XDG_DATA_HOME"), *old_home = getenv("HOME");
    char xdg[600] = "", home[600] = "";
    if (old_xdg) snprintf(xdg, sizeof xdg, "%s", old_xdg);
    if (old_home) snprintf(home, sizeof home, "%s", old_home);
    setenv("XDG_DATA_HOME", "/data/x", 1);
    RS_CHECK(rs_looklib_default_dir(out, sizeof out, &err) == RS_OK && strcmp(out, "/data/x/rouge/looks") == 0, "%s", out);
    setenv("XDG_DATA_HOME", "relative/ignored", 1);  // the spec: relative paths are invalid, ignore them
    setenv("HOME", "/home/u", 1);
    RS_CHECK(rs_looklib_default_dir(out, sizeof out, &err) == RS_OK && strcmp(out, "/home/u/.local/share/rouge/looks") == 0,
             "%s", out);
    unsetenv("XDG_DATA_HOME");
    unsetenv("HOME");
    RS_CHECK(rs_looklib_default_dir(out, sizeof out, &err) == RS_ERR_ARG && strstr(err.msg, "--looks"), "%s", err.msg);
    if (xdg[0]) setenv("XDG_DATA_HOME", xdg, 1);
    if (home[0]) setenv("HOME", home, 1);
}

static void test_unwritable_folder_fails_cleanly(void)
{
    char dir[600];
    rs_error err = {0};
    // A file where the folder should be.
    snprintf(dir, sizeof dir, "%s/looklib_file", rs_test_out_dir());
    REQUIRE(rs_file_write_atomic(dir, "x", 1, &err) == RS_OK);
    RS_CHECK(rs_looklib_save(dir, "a", "x", 1, NULL, false, &err) == RS_ERR_IO && strstr(err.msg, "looklib_file"),
             "%s", err.msg);
    rs_looklib_entry *e = NULL;
    uint32_t n = 0;
    RS_CHECK(rs_looklib_list(dir, &e, &n, &err) == RS_ERR_IO, "listing a file");
    free(e);
}

// A saver killed mid-save (SIGKILL) leaves .NAME.look.tmp.PID: the next save or rm of that name removes
// the ones whose process is gone, and keeps a live saver's.
static void test_stale_temporaries_of_dead_savers_are_removed(void)
{
    char dir[600], dead[800], dead_png[800], live[800];
    rs_error err = {0};
    fresh_dir("stale", dir, sizeof dir);
    REQUIRE(mkdir(dir, 0755) == 0 || errno == EEXIST);
    pid_t pid = fork();
    REQUIRE(pid >= 0);
    if (pid == 0) _exit(0);
    waitpid(pid, NULL, 0);  // now a PID no process has
    snprintf(dead, sizeof dead, "%s/.Evening.look.tmp.%ld", dir, (long)pid);
    snprintf(dead_png, sizeof dead_png, "%s/.Evening.png.tmp.%ld", dir, (long)pid);
    snprintf(live, sizeof live, "%s/.Evening.look.tmp.%ld", dir, (long)getppid());
    REQUIRE(rs_file_write_atomic(dead, "x", 1, &err) == RS_OK && rs_file_write_atomic(dead_png, "x", 1, &err) == RS_OK);
    REQUIRE(rs_file_write_atomic(live, "x", 1, &err) == RS_OK);
    RS_CHECK(rs_looklib_save(dir, "Evening", "x", 1, NULL, false, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(access(dead, F_OK) != 0 && access(dead_png, F_OK) != 0, "a dead saver's temporaries stayed");
    RS_CHECK(access(live, F_OK) == 0, "a live saver's temporary was removed");
    // rm of a name that only has a dead temporary left: the temporary goes, the answer is "no look".
    REQUIRE(rs_file_write_atomic(dead, "x", 1, &err) == RS_OK);
    RS_CHECK(rs_looklib_remove(dir, "Evening", &err) == RS_OK, "%s", err.msg);
    RS_CHECK(rs_looklib_remove(dir, "Evening", &err) == RS_ERR_ARG, "second rm");
    RS_CHECK(access(dead, F_OK) != 0, "rm left a dead saver's temporary");
    unlink(live);
}

// A failure writing the temporary (here a directory in its place; a full disk alike) names the look,
// not the hidden temporary.
static void test_write_failure_names_the_look(void)
{
    char dir[600], tmp[800];
    rs_error err = {0};
    fresh_dir("full", dir, sizeof dir);
    REQUIRE(mkdir(dir, 0755) == 0 || errno == EEXIST);
    snprintf(tmp, sizeof tmp, "%s/.Evening.look.tmp.%ld", dir, (long)getpid());
    REQUIRE(mkdir(tmp, 0755) == 0);
    RS_CHECK(rs_looklib_save(dir, "Evening", "x", 1, NULL, false, &err) == RS_ERR_IO && strstr(err.msg, "/Evening.look") &&
                 !strstr(err.msg, ".tmp."), "%s", err.msg);
    rmdir(tmp);
}

int main(int argc, char **argv)
{
    rs_test_init(argc, argv);
    RS_RUN(test_save_list_load_delete);
    RS_RUN(test_name_clash_is_refused_unless_overwriting);
    RS_RUN(test_bad_names_are_refused_with_a_reason);
    RS_RUN(test_default_folder_follows_xdg);
    RS_RUN(test_unwritable_folder_fails_cleanly);
    RS_RUN(test_stale_temporaries_of_dead_savers_are_removed);
    RS_RUN(test_write_failure_names_the_look);
    return rs_test_finish();
}
