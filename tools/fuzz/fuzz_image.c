// fuzz_image.c — libFuzzer entry point for texture decoding (tools/pack/image_load.c): PNG through libpng
// (src/core/image.c) and JPEG through stb_image, chosen by content, with the size limits checked before
// pixels are allocated. Built and run by `make fuzz` (tools/fuzz.sh, FUZZ_TARGETS image); seeds: the
// JPEG and PNG files of tests/fixtures/import and tests/fixtures/image. Any input must decode to an
// image within the limits or fail with a message.
#include "pack/import.h"

#include <stddef.h>
#include <stdint.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rs_image img = {0};
    rs_error err = {0};
    if (rs_image_decode_any(data, size, "fuzz", &img, &err) == RS_OK) {
        if (!img.pixels || img.width < 1 || img.height < 1 || img.width > RS_IMAGE_MAX_DIM || img.height > RS_IMAGE_MAX_DIM ||
            (uint64_t)img.width * (uint64_t)img.height > RS_IMPORT_MAX_TEXTURE_PIXELS)
            __builtin_trap();
        rs_image_free(&img);
    } else if (err.msg[0] == 0) {
        __builtin_trap();
    }
    return 0;
}
