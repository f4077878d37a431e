// fuzz_envmap.c — libFuzzer entry point for rouge-env's image readers (tools/env/env_read.c: Radiance .hdr
// through stb_image with a structure walk before it, OpenEXR through exr_read.cpp from memory) and the
// light search behind them. Built and run by `make fuzz` (tools/fuzz.sh, which compiles exr_read.cpp with
// clang++ and links OpenEXR; OpenEXR itself is not instrumented). Seeds: tests/fixtures/env/ (tiny .hdr
// and .exr files, damaged ones). Maps are capped at 256 x 128 here so that a claimed size cannot make an
// input slow; any input must read or fail cleanly with a message naming it.
#include "env/env_bake.h"
#include "env/env_read.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rs_envmap m = {0}, small = {0};
    rs_error err = {0};
    if (rs_envmap_read_memory(data, size, "(fuzz)", 256, &m, &err) != RS_OK) {
        if (m.rgb != NULL || strncmp(err.msg, "(fuzz): ", 8) != 0) __builtin_trap();
        return 0;
    }
    if (m.w < RS_ENVMAP_MIN_WIDTH || m.w > 256 || m.w != 2 * m.h) __builtin_trap();
    for (size_t i = 0; i < (size_t)m.w * m.h * 3; i++)
        if (!(m.rgb[i] >= 0.0f && m.rgb[i] <= 1e9f)) __builtin_trap();
    // Whatever the pixels, the light search and SH stay finite.
    if (rs_envmap_resample(&m, 32, &small, &err) == RS_OK) {
        rs_env_light L;
        float sh[9][3];
        if (rs_env_find_light(&small, NULL, &L, NULL, &err) != RS_OK) __builtin_trap();
        rs_env_project_sh(&small, sh);
        for (int k = 0; k < 3; k++)
            if (!isfinite(L.dir[k]) || !isfinite(L.color[k]) || !isfinite(sh[0][k])) __builtin_trap();
    }
    rs_envmap_free(&small);
    rs_envmap_free(&m);
    return 0;
}
