// fuzz_ply.c — libFuzzer entry point for the PLY reader (tools/pack/ply.c). Built by `make fuzz` with clang:
//   clang -g -O1 -fsanitize=fuzzer,address,undefined -Isrc -Itools tools/fuzz/fuzz_ply.c tools/pack/ply.c src/core/core.c
// Seed corpus: tests/fixtures/ply/. Any input must parse or fail cleanly: no crash, leak, hang or
// allocation beyond a small multiple of the input size.
#include "pack/ply.h"

#include <stddef.h>
#include <stdint.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rs_ply_mesh *m = NULL;
    rs_error err = {0};
    if (rs_ply_load_memory(data, size, &m, &err) == RS_OK) rs_ply_destroy(m);
    return 0;
}
