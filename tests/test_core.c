// test_core.c — the core helpers (src/core/core.c): terminal-safe text for messages that quote files.
#include "support/harness.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char *clean(const char *in, size_t cap)
{
    static char out[256];
    rs_text_sanitize(out, cap, in, strlen(in));
    return out;
}

static void test_sanitize_escapes_control_bytes(void)
{
    RS_CHECK(!strcmp(clean("a\033[2Jb\x7f\n", 256), "a\\x1b[2Jb\\x7f\\x0a"), "%s", clean("a\033[2Jb\x7f\n", 256));
}

static void test_sanitize_escapes_bidi_overrides_and_c1(void)
{
    const char *in = "x\xe2\x80\xaey\xe2\x81\xa6z\xc2\x9b";  // U+202E, U+2066, U+009B (CSI)
    RS_CHECK(!strcmp(clean(in, 256), "x\\u{202e}y\\u{2066}z\\u{009b}"), "%s", clean(in, 256));
}

static void test_sanitize_keeps_text_and_escapes_invalid_utf8(void)
{
    RS_CHECK(!strcmp(clean("caf\xc3\xa9 \xe6\x97\xa5", 256), "caf\xc3\xa9 \xe6\x97\xa5"), "valid UTF-8 kept");
    RS_CHECK(!strcmp(clean("caf\xe9!", 256), "caf\\xe9!"), "Latin-1: %s", clean("caf\xe9!", 256));
    RS_CHECK(!strcmp(clean("\xc0\xaf", 256), "\\xc0\\xaf"), "overlong: %s", clean("\xc0\xaf", 256));
}

static void test_sanitize_cuts_whole_characters(void)
{
    // 6 bytes of room: "ab" then an escape of 4 would overflow, so it stops before it.
    RS_CHECK(!strcmp(clean("ab\033cd", 6), "ab"), "%s", clean("ab\033cd", 6));
    RS_CHECK(!strcmp(clean("a\xc3\xa9", 3), "a"), "%s", clean("a\xc3\xa9", 3));
}

static void test_errors_are_sanitised(void)
{
    rs_error err = {0};
    rs_fail(&err, RS_ERR_FORMAT, "unknown keyword '%s'", "\033]0;pwned\007");
    RS_CHECK(!strcmp(err.msg, "unknown keyword '\\x1b]0;pwned\\x07'"), "%s", err.msg);
}

// One sRGB transfer function for the CPU (makeup, composite background, image metrics once had three that
// disagreed on < vs <= at the threshold): linear at and below it, as IEC 61966-2-1 says, continuous there.
static void test_srgb_threshold_and_round_trip(void)
{
    RS_CHECK(rs_srgb_to_linear(0.04045f) == 0.04045f / 12.92f, "at the threshold: %.9g", rs_srgb_to_linear(0.04045f));
    RS_CHECK(rs_linear_to_srgb(0.0031308f) == 0.0031308f * 12.92f, "at the threshold: %.9g", rs_linear_to_srgb(0.0031308f));
    float above = rs_srgb_to_linear(0.04045f + 1e-6f), at = rs_srgb_to_linear(0.04045f);
    RS_CHECK(fabsf(above - at) < 1e-6f, "a step at the threshold: %.9g vs %.9g", at, above);
    float worst = 0;
    for (int q = 0; q < 256; q++) worst = fmaxf(worst, fabsf(rs_linear_to_srgb(rs_srgb_to_linear(q / 255.0f)) - q / 255.0f));
    RS_CHECK(worst < 1e-5f, "8-bit round trip off by %g", worst);
    RS_CHECK(rs_linear_to_srgb(-1) == 0 && fabsf(rs_linear_to_srgb(2) - 1.0f) < 1e-6f, "not clamped");
}

// The one number parser: whole tokens only, finite, in range; lists need exactly n numbers.
static void test_parse_number_and_lists(void)
{
    double v = 0, l[3] = {0};
    float f = 0;
    RS_CHECK(rs_parse_number("2.5", 0, 10, &v) && v == 2.5, "2.5");
    RS_CHECK(rs_parse_number("-1e-3", -1, 1, &v) && v == -1e-3, "-1e-3");
    const char *bad[] = {"", " 1", "1 ", "1x", "nan", "inf", "1e999", "0x", NULL};
    for (int i = 0; i < (int)(sizeof bad / sizeof *bad); i++)
        RS_CHECK(!rs_parse_number(bad[i], -1e300, 1e300, &v), "'%s' refused", bad[i] ? bad[i] : "(null)");
    RS_CHECK(!rs_parse_number("11", 0, 10, &v) && !rs_parse_number("-0.1", 0, 10, &v), "range");
    RS_CHECK(rs_parse_float("3.25", &f) && f == 3.25f && !rs_parse_float("1e39", &f), "float range");
    RS_CHECK(rs_parse_list("0.1,-0.2", ',', 2, -1, 1, l) && l[0] == 0.1 && l[1] == -0.2, "pair");
    RS_CHECK(rs_parse_list("1,2,3", ',', 3, 0, 3, l) && l[2] == 3, "triple");
    RS_CHECK(!rs_parse_list("1,2", ',', 3, 0, 3, l) && !rs_parse_list("1,2,3,4", ',', 3, 0, 9, l) &&
                 !rs_parse_list("1,,3", ',', 3, 0, 3, l) && !rs_parse_list("1,2,5", ',', 3, 0, 3, l),
             "short, long, empty and out-of-range lists refused");
}

// Growth doubles from 64, keeps contents, refuses sizes that overflow and leaves the array as it was.
static void test_array_grow(void)
{
    uint32_t *a = NULL, cap = 0;
    RS_CHECK(rs_array_grow((void **)&a, &cap, 1, sizeof *a) && cap == 64, "first growth to 64 (cap %u)", cap);
    for (uint32_t i = 0; i < 64; i++) a[i] = i;
    RS_CHECK(rs_array_grow((void **)&a, &cap, 300, sizeof *a) && cap == 512 && a[63] == 63, "grows to 512 keeping data");
    uint32_t *keep = a, kc = cap;
    RS_CHECK(!rs_array_grow((void **)&a, &cap, UINT32_MAX, (size_t)1 << 40) && a == keep && cap == kc,
             "an overflowing size is refused and the array kept");
    free(a);
}

int main(int argc, char **argv)
{
    rs_test_init(argc, argv);
    RS_RUN(test_sanitize_escapes_control_bytes);
    RS_RUN(test_sanitize_escapes_bidi_overrides_and_c1);
    RS_RUN(test_sanitize_keeps_text_and_escapes_invalid_utf8);
    RS_RUN(test_sanitize_cuts_whole_characters);
    RS_RUN(test_errors_are_sanitised);
    RS_RUN(test_srgb_threshold_and_round_trip);
    RS_RUN(test_parse_number_and_lists);
    RS_RUN(test_array_grow);
    return rs_test_finish();
}
