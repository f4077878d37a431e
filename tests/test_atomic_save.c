// test_atomic_save.c — saving a look or a PNG is atomic (temp file + fsync + rename, rs_file_write_atomic):
// a child process saves two known contents in turn, over and over, and is SIGKILLed at a random moment;
// every time, the file under the target name must be byte for byte the old or the new version, never
// a torn mix, an empty file or missing. A control runs the same loop on a plain fopen/fwrite writer and
// must catch it tearing the file, which shows the kill loop really lands in the middle of writes.
// The loops run until enough kills have landed inside a save (counted in memory the child shares), not
// for a fixed time: on a busy machine the child may not run between fork and kill, and a timed loop
// then proves less (it once had to run alone after the other tests).
#define _DEFAULT_SOURCE  // MAP_ANONYMOUS
#include "support/harness.h"
#include "formats/look.h"

#include <dirent.h>
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#define MID_SAVE_KILLS 150  // kills that must land inside a save (the control: until a file is torn)
#define MAX_SECONDS 60.0    // a bound for a machine too busy to let the child run; the checks then fail

// What the child saves: content 0 or 1 to `path`, returning false on failure.
typedef bool (*save_fn)(const void *ctx, int which, const char *path);

typedef struct kill_stats {
    int kills;          // children killed mid-loop
    int mid_save;       // ... while inside a save (begun, not finished)
    int old_or_new;     // target held one of the two complete versions after the kill
    int torn;           // target held anything else
    int missing;        // target absent
    int temps;          // temp files left by killed children (expected: the rename never happened)
    char why[160];      // first torn/missing/child failure
} kill_stats;

static uint64_t rng = 0x2545F4914F6CDD1Du;
static double rand_unit(void)
{
    rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
    return (double)(rng >> 11) / 9007199254740992.0;
}

static void sleep_us(double us)
{
    struct timespec ts = {(time_t)(us / 1e6), (long)((us - (double)(time_t)(us / 1e6) * 1e6) * 1e3)};
    while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {}
}

// Removes "<base>.tmp*" files next to the target (left by killed children) and counts them.
static int remove_temps(const char *dir, const char *base)
{
    DIR *d = opendir(dir);
    if (!d) return 0;
    char prefix[256], path[1024];
    snprintf(prefix, sizeof prefix, "%s.tmp", base);
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        if (strncmp(e->d_name, prefix, strlen(prefix)) != 0) continue;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        if (unlink(path) == 0) n++;
    }
    closedir(d);
    return n;
}

// The saving child's progress, in memory it shares with the parent (read after the child is reaped).
typedef struct progress {
    volatile long begun, done;
} progress;

// The kill loop. `versions` are the exact bytes of content 0 and 1; the target starts as version 0. It
// stops once `mid_save` kills have landed inside a save, or (stop_at_torn) at the first torn or missing
// file, or after MAX_SECONDS.
static kill_stats kill_loop(const char *dir, const char *base, save_fn save, const void *ctx, const void *v0,
                            size_t n0, const void *v1, size_t n1, int mid_save, bool stop_at_torn)
{
    kill_stats ks = {0};
    progress *pg = mmap(NULL, sizeof *pg, PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
    if (pg == MAP_FAILED) {
        snprintf(ks.why, sizeof ks.why, "mmap: %s", strerror(errno));
        return ks;
    }
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, base);
    rs_error err = {0};
    if (!save(ctx, 0, path)) {
        snprintf(ks.why, sizeof ks.why, "first save failed");
        munmap(pg, sizeof *pg);
        return ks;
    }
    // One save's duration sets the range of kill delays, so kills land anywhere in a save.
    double t0 = rs_time_now();
    for (int i = 0; i < 3; i++) save(ctx, i & 1, path);
    double save_us = (rs_time_now() - t0) / 3 * 1e6;
    save(ctx, 0, path);
    double start = rs_time_now();
    while (ks.mid_save < mid_save && !(stop_at_torn && ks.torn + ks.missing > 0) &&
           rs_time_now() - start < MAX_SECONDS) {
        fflush(NULL);
        pg->begun = pg->done = 0;
        pid_t pid = fork();
        if (pid < 0) break;
        if (pid == 0) {
            for (int i = 1;; i++) {
                pg->begun++;
                if (!save(ctx, i & 1, path)) _exit(3);
                pg->done++;
            }
        }
        sleep_us(rand_unit() * 2.5 * save_us + 20.0);
        kill(pid, SIGKILL);
        int status = 0;
        while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {}
        if (!WIFSIGNALED(status)) {
            if (!ks.why[0]) snprintf(ks.why, sizeof ks.why, "the saving child stopped by itself (status %d)", status);
            break;
        }
        ks.kills++;
        if (pg->begun > pg->done) ks.mid_save++;
        void *data = NULL;
        size_t len = 0;
        if (rs_file_read_all(path, 1u << 28, &data, &len, &err) != RS_OK) {
            ks.missing++;
            if (!ks.why[0]) snprintf(ks.why, sizeof ks.why, "after kill %d: %s", ks.kills, err.msg);
        } else if ((len == n0 && memcmp(data, v0, n0) == 0) || (len == n1 && memcmp(data, v1, n1) == 0)) {
            ks.old_or_new++;
        } else {
            ks.torn++;
            if (!ks.why[0])
                snprintf(ks.why, sizeof ks.why, "after kill %d: %zu bytes, neither version (%zu or %zu bytes)",
                         ks.kills, len, n0, n1);
        }
        free(data);
        ks.temps += remove_temps(dir, base);
    }
    munmap(pg, sizeof *pg);
    return ks;
}

static const char *scratch(void)
{
    static char dir[512];
    snprintf(dir, sizeof dir, "%s/atomic", rs_test_out_dir());
    mkdir(dir, 0755);
    return dir;
}

// ---- looks ----

// A plane of 64 x 64 splats facing +z, face height 1.
static rs_splat_cloud *plane(void)
{
    enum { K = 64 };
    rs_splat *s = calloc(K * K, sizeof *s);
    if (!s) return NULL;
    for (int y = 0; y < K; y++)
        for (int x = 0; x < K; x++)
            s[y * K + x] = (rs_splat){{-0.5f + x / (K - 1.0f), -0.5f + y / (K - 1.0f), 0.0f}, {0, 0, 1},
                                      1.0f / (K - 1), {200, 150, 130}, 1};
    rs_splat_header h;
    memset(&h, 0, sizeof h);
    h.face_height = 1.0f;
    h.lod_count = 1;
    h.lods[0] = K * K;
    rs_splat_cloud *c = NULL;
    rs_error err = {0};
    RS_CHECK(rs_splat_create(s, K * K, &h, &c, &err) == RS_OK, "%s", err.msg);
    free(s);
    return c;
}

// A look of `stamps` stamps along a zigzag (a few hundred kB of text: a save takes a while).
static rs_makeup *painted(const rs_splat_cloud *c, const char *cosmetic, int stamps, float phase)
{
    rs_makeup *mk = NULL;
    rs_error err = {0};
    if (!c || rs_makeup_create(c, NULL, &mk, &err) != RS_OK) return NULL;
    rs_makeup_stamp_desc d = {.view_dir = {0, 0, 1}, .radius = 0.03f, .opacity = 0.4f, .pressure = 1.0f,
                              .cosmetic = rs_cosmetic_find(cosmetic)};
    rs_makeup_begin_stroke(mk);
    for (int i = 0; i < stamps; i++) {
        float t = (float)i / (float)stamps;
        d.pos[0] = -0.4f + 0.8f * t;
        d.pos[1] = 0.3f * ((i / 50) % 2 ? 1.0f : -1.0f) * (float)(i % 50) / 50.0f + phase;
        rs_makeup_stamp_info info;
        if (rs_makeup_stamp(mk, &d, &info, &err) != RS_OK) break;
    }
    rs_makeup_end_stroke(mk, &err);
    return mk;
}

static bool save_look(const void *ctx, int which, const char *path)
{
    rs_makeup *const *mk = ctx;
    rs_error err = {0};
    return rs_look_save(mk[which], path, &err) == RS_OK;
}

static void test_look_save_killed_midway_leaves_old_or_new_look(void)
{
    rs_splat_cloud *c = plane();
    rs_makeup *mk[2] = {painted(c, "blush", 3000, 0.0f), painted(c, "lip_gloss", 2500, 0.1f)};
    RS_REQUIRE(mk[0] && mk[1], "cannot paint the two looks");
    char *v[2] = {NULL, NULL};
    size_t n[2] = {0, 0};
    rs_error err = {0};
    for (int i = 0; i < 2; i++) RS_REQUIRE(rs_look_write_memory(mk[i], &v[i], &n[i], &err) == RS_OK, "%s", err.msg);
    RS_REQUIRE(n[0] != n[1] || memcmp(v[0], v[1], n[0]) != 0, "the two looks are the same");
    kill_stats ks = kill_loop(scratch(), "kill.look", save_look, mk, v[0], n[0], v[1], n[1], MID_SAVE_KILLS, false);
    RS_CHECK(ks.mid_save >= MID_SAVE_KILLS, "only %d of %d kills inside a save in %.0f s (%s)", ks.mid_save, ks.kills,
             MAX_SECONDS, ks.why);
    RS_CHECK(ks.torn == 0 && ks.missing == 0 && !ks.why[0], "%d torn, %d missing of %d kills: %s", ks.torn,
             ks.missing, ks.kills, ks.why);
    // The saved look must also load: replaying it gives back one of the two layers' files.
    char path[1024];
    snprintf(path, sizeof path, "%s/kill.look", scratch());
    rs_makeup *back = painted(c, "blush", 0, 0.0f);
    rs_makeup_range dirty;
    RS_CHECK(back && rs_look_load(back, path, &dirty, &err) == RS_OK, "%s", err.msg);
    printf("# look: %d kills (%d inside a save), %d old-or-new, %d temp files left by killed saves (%zu/%zu bytes)\n",
           ks.kills, ks.mid_save, ks.old_or_new, ks.temps, n[0], n[1]);
    // O_TMPFILE: a save killed while writing leaves no named file (the tiny link-to-rename window aside).
    RS_CHECK(ks.temps <= ks.kills / 20, "%d of %d killed saves left a temp file", ks.temps, ks.kills);
    rs_makeup_destroy(back);
    free(v[0]), free(v[1]);
    rs_makeup_destroy(mk[0]), rs_makeup_destroy(mk[1]);
    rs_splat_destroy(c);
}

// ---- PNG screenshots ----

static bool noise_image(rs_image *img, uint32_t seed)
{
    rs_error err = {0};
    if (rs_image_create(256, 256, 4, img, &err) != RS_OK) return false;
    for (size_t i = 0; i < (size_t)256 * 256 * 4; i++) {
        seed = seed * 1664525u + 1013904223u;
        img->pixels[i] = (uint8_t)(seed >> 24);  // noise: PNG cannot compress it, the file is ~260 kB
    }
    return true;
}

static bool save_png(const void *ctx, int which, const char *path)
{
    const rs_image *img = ctx;
    rs_error err = {0};
    return rs_image_write_png(path, &img[which], &err) == RS_OK;
}

static void test_png_save_killed_midway_leaves_old_or_new_png(void)
{
    rs_image img[2] = {{0}, {0}};
    RS_REQUIRE(noise_image(&img[0], 1) && noise_image(&img[1], 2), "cannot make the images");
    // The exact bytes of each version: the encoder is deterministic.
    void *v[2] = {NULL, NULL};
    size_t n[2] = {0, 0};
    char path[1024];
    rs_error err = {0};
    for (int i = 0; i < 2; i++) {
        snprintf(path, sizeof path, "%s/version%d.png", scratch(), i);
        RS_REQUIRE(rs_image_write_png(path, &img[i], &err) == RS_OK, "%s", err.msg);
        RS_REQUIRE(rs_file_read_all(path, 1u << 24, &v[i], &n[i], &err) == RS_OK, "%s", err.msg);
    }
    kill_stats ks = kill_loop(scratch(), "kill.png", save_png, img, v[0], n[0], v[1], n[1], MID_SAVE_KILLS, false);
    RS_CHECK(ks.mid_save >= MID_SAVE_KILLS, "only %d of %d kills inside a save in %.0f s (%s)", ks.mid_save, ks.kills,
             MAX_SECONDS, ks.why);
    RS_CHECK(ks.torn == 0 && ks.missing == 0 && !ks.why[0], "%d torn, %d missing of %d kills: %s", ks.torn,
             ks.missing, ks.kills, ks.why);
    printf("# png: %d kills (%d inside a save), %d old-or-new, %d temp files left by killed saves (%zu/%zu bytes)\n",
           ks.kills, ks.mid_save, ks.old_or_new, ks.temps, n[0], n[1]);
    RS_CHECK(ks.temps <= ks.kills / 20, "%d of %d killed saves left a temp file", ks.temps, ks.kills);
    free(v[0]), free(v[1]);
    rs_image_free(&img[0]), rs_image_free(&img[1]);
}

// ---- control ----

typedef struct naive_ctx {
    const void *data[2];
    size_t len[2];
} naive_ctx;

// What atomic saving prevents: truncate the target, then write it in pieces.
static bool save_naive(const void *ctx, int which, const char *path)
{
    const naive_ctx *c = ctx;
    FILE *f = fopen(path, "wb");
    if (!f) return false;
    const unsigned char *p = c->data[which];
    for (size_t done = 0; done < c->len[which]; done += 4096) {
        size_t k = RS_MIN((size_t)4096, c->len[which] - done);
        if (fwrite(p + done, 1, k, f) != k) break;
        fflush(f);
    }
    return fclose(f) == 0;
}

// Where a temp file of ours was left by a writer that is gone (killed before O_TMPFILE existed, or on a
// filesystem without it), the next save of the same target removes it; other files are left alone.
static void test_next_save_removes_stale_temps_of_dead_writers(void)
{
    pid_t child = fork();
    if (child == 0) _exit(0);
    waitpid(child, NULL, 0);  // now a pid with no process
    char target[1024], stale[1100], alive[1100], other[1100];
    snprintf(target, sizeof target, "%s/stale.png", scratch());
    snprintf(stale, sizeof stale, "%s.tmp.%ld", target, (long)child);
    snprintf(alive, sizeof alive, "%s.tmp.%ld", target, (long)getppid());
    snprintf(other, sizeof other, "%s/stale.png.tmp.notapid", scratch());
    const char *files[] = {stale, alive, other};
    for (int i = 0; i < 3; i++) {
        FILE *f = fopen(files[i], "w");
        RS_REQUIRE(f, "cannot create %s", files[i]);
        fputs("orphan", f);
        fclose(f);
    }
    rs_error err = {0};
    RS_REQUIRE(rs_file_write_atomic(target, "new", 3, &err) == RS_OK, "%s", err.msg);
    struct stat st;
    RS_CHECK(stat(stale, &st) != 0, "the dead writer's temp file is still there");
    RS_CHECK(stat(alive, &st) == 0, "a live process's temp file was removed");
    RS_CHECK(stat(other, &st) == 0, "a file not of our pattern was removed");
    unlink(alive), unlink(other), unlink(target);
}

static void test_kill_loop_catches_a_non_atomic_writer(void)
{
    enum { N = 256 * 1024 };
    unsigned char *a = malloc(N), *b = malloc(N);
    RS_REQUIRE(a && b, "out of memory");
    memset(a, 'a', N);
    memset(b, 'b', N);
    naive_ctx ctx = {{a, b}, {N, N}};
    kill_stats ks = kill_loop(scratch(), "naive.bin", save_naive, &ctx, a, N, b, N, MID_SAVE_KILLS, true);
    RS_CHECK(ks.torn + ks.missing > 0, "no torn file in %d kills (%d inside a save): the kill loop tests nothing",
             ks.kills, ks.mid_save);
    printf("# control: the first torn file after %d kills (%d inside a save) with a plain fopen/fwrite writer\n",
           ks.kills, ks.mid_save);
    free(a), free(b);
}

int main(int argc, char **argv)
{
    rs_test_init(argc, argv);
    RS_RUN(test_look_save_killed_midway_leaves_old_or_new_look);
    RS_RUN(test_png_save_killed_midway_leaves_old_or_new_png);
    RS_RUN(test_next_save_removes_stale_temps_of_dead_writers);
    RS_RUN(test_kill_loop_catches_a_non_atomic_writer);
    return rs_test_finish();
}
