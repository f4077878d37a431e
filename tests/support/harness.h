// harness.h — the tiny test framework every tests/test_*.c program uses; tests/run.sh sums them up.
//
// Each program prints one line per test: "ok - name", "FAIL - name: why" or "skip - name: why",
// and exits non-zero if any failed. Tests run from the repository root.
//
//   static void test_crc_known_value(void) { RS_CHECK(rs_crc32(0, "a", 1) == 0xe8b7be43u, "crc"); }
//   int main(int argc, char **argv) {
//       rs_test_init(argc, argv);
//       RS_RUN(test_crc_known_value);
//       return rs_test_finish();
//   }
#ifndef RS_TEST_HARNESS_H
#define RS_TEST_HARNESS_H

#include "core/core.h"
#include "core/image.h"

void rs_test_init(int argc, char **argv);  // argv[1..]: substrings selecting tests to run; "-SUB" leaves out those matching SUB
void rs_test_run(const char *name, void (*fn)(void));
int rs_test_finish(void);
#define RS_RUN(fn) rs_test_run(#fn, fn)

// Records a failure for the current test (first message kept), returns cond.
bool rs_test_check(bool cond, const char *file, int line, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
#define RS_CHECK(cond, ...) rs_test_check((cond), __FILE__, __LINE__, __VA_ARGS__)
// Like RS_CHECK but returns from the test function on failure.
#define RS_REQUIRE(cond, ...) do { if (!RS_CHECK(cond, __VA_ARGS__)) return; } while (0)
// Marks the current test skipped (e.g. optional shared data absent); return right after.
void rs_test_skip(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

// Output folder for artefacts of failing tests: <build>/test-out (created on demand).
const char *rs_test_out_dir(void);
// Path of optional shared data (../shared/data/<rel>), or NULL when absent (then skip).
const char *rs_test_shared_path(const char *rel);

// Compares `actual` with the committed golden PNG tests/golden/<name>.png using the two-number tolerance
// (at most max_frac of pixels may differ by more than threshold) plus a minimum PSNR. On failure writes
// <out>/<name>.actual.png and <name>.diff.png and records the metrics in the failure message.
// RS_UPDATE_GOLDEN=1 rewrites the golden instead (then inspect it before committing).
bool rs_test_golden(const char *name, const rs_image *actual, int threshold, double max_frac, double min_psnr);
// Saves an artefact image to <out>/<name>.png (for debugging and for people to look at).
void rs_test_save(const char *name, const rs_image *img);

#endif
