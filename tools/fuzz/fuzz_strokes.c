// fuzz_strokes.c — libFuzzer entry point for the stroke-file parser (src/formats/strokes.c). Build and run:
//   clang -g -O1 -fsanitize=fuzzer,address,undefined -Isrc tools/fuzz/fuzz_strokes.c src/formats/strokes.c \
//       src/makeup/cosmetics.c src/core/core.c -o /tmp/fuzz_strokes && /tmp/fuzz_strokes tests/fixtures/strokes
// Any input must parse or fail cleanly (no crash, leak, hang or large allocation), and whatever parses
// must write back to text that parses to the same document (the writer and parser agree).
#include "formats/strokes.h"

#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rs_strokes *doc = NULL, *back = NULL;
    rs_error err = {0};
    if (rs_strokes_parse(data, size, &doc, &err) != RS_OK) return 0;
    char *text = NULL;
    size_t len = 0;
    if (rs_strokes_write_memory(doc, &text, &len, &err) != RS_OK) __builtin_trap();
    if (rs_strokes_parse(text, len, &back, &err) != RS_OK) __builtin_trap();
    // (memcmp only when there are samples: both arrays may be NULL, and memcmp(NULL, NULL, 0) is UB.)
    if (back->count != doc->count || back->sample_count != doc->sample_count ||
        (doc->sample_count > 0 && memcmp(back->samples, doc->samples, doc->sample_count * sizeof *doc->samples) != 0))
        __builtin_trap();
    for (uint32_t i = 0; i < doc->count; i++)
        if (!rs_cosmetic_equal(&doc->strokes[i].cosmetic, &back->strokes[i].cosmetic)) __builtin_trap();
    free(text);
    rs_strokes_destroy(doc);
    rs_strokes_destroy(back);
    return 0;
}
