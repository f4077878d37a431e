// fuzz_import.c — libFuzzer entry point for the assimp import path (tools/pack/import_assimp.c), as
// `rouge-pack MODEL -o OUT.rsf` runs it: rs_import_load_memory (format by content: GLB, glTF JSON, STL,
// FBX, COLLADA, else OBJ) -> welding, texture pages and embedded images (decoded with the size limits)
// -> for small models the conversion (per-page sampling, face frame, regions). Built and run by `make
// fuzz` (tools/fuzz.sh, FUZZ_TARGETS import); seeds: tests/fixtures/import. Nothing touches the disk:
// the memory import serves only the model itself. Any input must import or fail with a message.
#include "pack/import.h"
#include "pack/pack.h"

#include <stddef.h>
#include <stdint.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static const char *hint_of(const uint8_t *d, size_t n)
{
    if (n >= 4 && !memcmp(d, "glTF", 4)) return "glb";
    if (n >= 1 && d[0] == '{') return "gltf";
    if (n >= 5 && !memcmp(d, "solid", 5)) return "stl";
    if (n >= 7 && !memcmp(d, "Kaydara", 7)) return "fbx";
    if (n >= 1 && d[0] == '<') return "dae";
    return "obj";
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rs_import_scene *s = NULL;
    rs_error err = {0};
    if (rs_import_load_memory(data, size, hint_of(data, size), &s, &err) != RS_OK) {
        if (err.msg[0] == 0) __builtin_trap();
        return 0;
    }
    rs_image *pages = NULL;
    if (rs_import_load_pages(s, &pages, &err) != RS_OK && err.msg[0] == 0) __builtin_trap();
    // Few samples, small models, no occlusion pass: the converter has its own harness (fuzz_convert).
    if (s->mesh->vertex_count <= 5000) {
        rs_pack_desc d = {.points = 500, .no_ao = true, .pages = pages, .page_count = pages ? s->page_count : 0,
                          .declared_mm_per_unit = s->declared_mm_per_unit};
        rs_splat_cloud *c = NULL;
        if (rs_pack_convert(s->mesh, &d, &c, NULL, &err) == RS_OK) rs_splat_destroy(c);
        else if (err.msg[0] == 0) __builtin_trap();
    }
    rs_import_free_pages(pages, s->page_count);
    rs_import_destroy(s);
    return 0;
}
