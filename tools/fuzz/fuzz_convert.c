// fuzz_convert.c — libFuzzer entry point for the whole conversion path, as `rouge-pack IN.ply --preview
// P.png -o OUT.rsf` runs it: PLY reader -> converter (normals, radii, LOD, face frame, regions, encode) ->
// the preview rasteriser -> .rsf save -> load. Built and run by `make fuzz` (tools/fuzz.sh, FUZZ_TARGETS
// convert). Seeds: tests/fixtures/ply and the degenerate scans in tests/fixtures/bad/ply_*.
// Any input must convert or fail cleanly, and what converts must load back. The preview's float-to-int
// conversions are checked by -fsanitize=float-cast-overflow (a harness like this one found them).
#include "pack/pack.h"

#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rs_ply_mesh *m = NULL;
    rs_error err = {0};
    if (rs_ply_load_memory(data, size, &m, &err) != RS_OK) return 0;
    // Few samples per mesh: the sampler's cost is its own, not the input's, and fuzzing wants speed.
    rs_pack_desc d = {.points = 500};
    rs_splat_cloud *c = NULL;
    if (rs_pack_convert(m, &d, &c, NULL, &err) == RS_OK) {
        rs_image img = {0};
        if (rs_pack_preview(c, 32, &img, &err) == RS_OK) rs_image_free(&img);
        void *bytes = NULL;
        size_t len = 0;
        if (rs_splat_save_memory(c, &bytes, &len, &err) != RS_OK) __builtin_trap();
        rs_splat_cloud *back = NULL;
        if (rs_splat_load_memory(bytes, len, &back, &err) != RS_OK) __builtin_trap();
        rs_splat_destroy(back);
        free(bytes);
        rs_splat_destroy(c);
    } else if (err.msg[0] == 0) {
        __builtin_trap();
    }
    rs_ply_destroy(m);
    return 0;
}
