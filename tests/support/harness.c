// harness.c — see harness.h.
#define _POSIX_C_SOURCE 200809L
#include "support/harness.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

static struct {
    int argc;
    char **argv;
    int passed, failed, skipped;
    bool cur_failed, cur_skipped;
    char cur_msg[1024];
    char out_dir[512];
    char shared[1024];
} T;

void rs_test_init(int argc, char **argv)
{
    T.argc = argc;
    T.argv = argv;
    setvbuf(stdout, NULL, _IOLBF, 0);
}

// argv[1..]: substrings selecting tests; "-SUBSTRING" leaves out the tests it matches (tests/run.sh runs the
// slowest checks of a program as jobs of their own beside the rest).
static bool selected(const char *name)
{
    bool any = false, hit = false;
    for (int i = 1; i < T.argc; i++) {
        const char *a = T.argv[i];
        if (a[0] == '-') {
            if (a[1] && strstr(name, a + 1)) return false;
        } else {
            any = true;
            hit = hit || strstr(name, a);
        }
    }
    return !any || hit;
}

void rs_test_run(const char *name, void (*fn)(void))
{
    if (!selected(name)) return;
    T.cur_failed = T.cur_skipped = false;
    T.cur_msg[0] = 0;
    double t0 = rs_time_now();
    clock_t c0 = clock();  // the process's CPU time, every thread (llvmpipe's too): what a busy machine cannot skew
    fn();
    double dt = rs_time_now() - t0, cpu = (double)(clock() - c0) / CLOCKS_PER_SEC;
    if (T.cur_failed) {
        T.failed++;
        printf("FAIL - %s: %s\n", name, T.cur_msg);
    } else if (T.cur_skipped) {
        T.skipped++;
        printf("skip - %s: %s\n", name, T.cur_msg);
    } else {
        T.passed++;
        printf("ok - %s (%.2f s, %.2f s CPU)\n", name, dt, cpu);
    }
}

int rs_test_finish(void)
{
    return T.failed ? 1 : 0;
}

bool rs_test_check(bool cond, const char *file, int line, const char *fmt, ...)
{
    if (cond || T.cur_failed) return cond;
    T.cur_failed = true;
    int n = snprintf(T.cur_msg, sizeof T.cur_msg, "%s:%d: ", file, line);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(T.cur_msg + n, sizeof T.cur_msg - (size_t)n, fmt, ap);
    va_end(ap);
    return false;
}

void rs_test_skip(const char *fmt, ...)
{
    T.cur_skipped = true;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(T.cur_msg, sizeof T.cur_msg, fmt, ap);
    va_end(ap);
}

const char *rs_test_out_dir(void)
{
    if (!T.out_dir[0]) {
        const char *o = getenv("RS_TEST_OUT");
        const char *b = getenv("RS_BUILD");
        if (o && *o) snprintf(T.out_dir, sizeof T.out_dir, "%s", o);
        else snprintf(T.out_dir, sizeof T.out_dir, "%s/test-out", b && *b ? b : "build");
        // mkdir -p: tests may run straight from a build directory that has no test-out yet.
        for (char *p = T.out_dir + 1; *p; p++)
            if (*p == '/') {
                *p = 0;
                mkdir(T.out_dir, 0755);
                *p = '/';
            }
        mkdir(T.out_dir, 0755);
    }
    return T.out_dir;
}

const char *rs_test_shared_path(const char *rel)
{
    const char *root = getenv("RS_SHARED_DATA");
    snprintf(T.shared, sizeof T.shared, "%s/%s", root && *root ? root : "../shared/data", rel);
    return access(T.shared, R_OK) == 0 ? T.shared : NULL;
}

void rs_test_save(const char *name, const rs_image *img)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.png", rs_test_out_dir(), name);
    rs_error err = {0};
    if (rs_image_write_png(path, img, &err) != RS_OK) fprintf(stderr, "warning: %s\n", err.msg);
}

bool rs_test_golden(const char *name, const rs_image *actual, int threshold, double max_frac, double min_psnr)
{
    char path[1024];
    snprintf(path, sizeof path, "tests/golden/%s.png", name);
    rs_error err = {0};
    const char *upd = getenv("RS_UPDATE_GOLDEN");
    if (upd && *upd == '1') {
        if (rs_image_write_png(path, actual, &err) != RS_OK) return RS_CHECK(false, "%s", err.msg);
        return true;
    }
    rs_image golden = {0};
    if (rs_image_read_png(path, &golden, &err) != RS_OK)
        return RS_CHECK(false, "golden %s unreadable (%s); RS_UPDATE_GOLDEN=1 creates it", path, err.msg);
    rs_image_metrics m;
    bool ok = rs_image_compare(&golden, actual, threshold, &m, &err) == RS_OK;
    if (!ok) {
        RS_CHECK(false, "golden %s: %s", path, err.msg);
    } else if (m.frac_over > max_frac || m.psnr < min_psnr) {
        char a[600];
        snprintf(a, sizeof a, "%s.actual", name);
        rs_test_save(a, actual);
        rs_image diff = {0};
        if (rs_image_diff(&golden, actual, &diff, &err) == RS_OK) {
            snprintf(a, sizeof a, "%s.diff", name);
            rs_test_save(a, &diff);
            rs_image_free(&diff);
        }
        ok = RS_CHECK(false,
                      "golden %s: %.4f%% of pixels differ by > %d (allowed %.4f%%), PSNR %.2f dB (min %.1f), "
                      "max %d; see %s/%s.actual.png",
                      name, 100 * m.frac_over, threshold, 100 * max_frac, m.psnr, min_psnr, m.max_abs,
                      rs_test_out_dir(), name);
    }
    rs_image_free(&golden);
    return ok;
}
