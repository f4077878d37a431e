// import.h — the scan formats people have, read into the converter's mesh: PLY through rouge's own reader
// (ply.h), everything else (OBJ + MTL, glTF / GLB, FBX, STL, DAE, 3DS, OFF, ...) through assimp, plus the
// texture images their materials name (PNG through libpng, JPEG through libjpeg-turbo, BMP / TGA through
// stb_image).
//
// Does: route a file by its content (a "ply" magic line) or its extension; flatten an assimp scene into
// one triangle mesh (node transforms applied, polygons triangulated, vertices that share position, UV and
// material welded so the index graph is the surface), one texture page per material, per-triangle page
// ids; read the unit the format declares (glTF: metres; FBX: UnitScaleFactor; COLLADA: <unit>, applied
// by assimp); find each material's base-colour texture (glTF baseColorTexture, MTL map_Kd, also with
// spaces in the file name, embedded GLB / FBX images) and decode it with size limits checked before the
// pixels are allocated. Files are opened through our own I/O callbacks: regular files only, size-capped,
// below the model's folder unless allowed (rs_import_desc), so an MTL naming a FIFO, /dev/zero or
// /etc/passwd cannot hang the import or be read. Hostile structure (deep nesting, nodes that instance
// themselves, decompression and instancing bombs) is refused before assimp expands it, and assimp runs
// in a child process with memory and CPU limits (rs_import_load).
// Does not: sample, convert or write anything (pack.h), or keep animation, bones, cameras or lights.
//
//   rs_import_scene *s = NULL;
//   if (rs_import_load("head.obj", &s, &err) != RS_OK) { puts(err.msg); return 1; }
//   rs_image *pages = NULL;
//   if (rs_import_load_pages(s, &pages, &err) == RS_OK) ... rs_pack_convert(s->mesh, &desc, ...);
//   rs_import_free_pages(pages, s->page_count);
//   rs_import_destroy(s);
#ifndef RS_IMPORT_H
#define RS_IMPORT_H

#include "core/core.h"
#include "core/image.h"
#include "pack/ply.h"

#define RS_IMPORT_MAX_FILE ((size_t)2 << 30)    // any one file (model, MTL, .bin, texture): 2 GiB
#define RS_IMPORT_MAX_VERTICES (1u << 26)       // after triangulation, before welding
#define RS_IMPORT_MAX_TRIANGLES (1u << 27)
#define RS_IMPORT_MAX_PAGES 256                 // materials (texture pages)
// Before assimp reads a file (import_guard.c): nesting of elements, records and node hierarchies, and
// the nodes a hierarchy unrolls to when nodes instance others.
#define RS_IMPORT_MAX_DEPTH 256
#define RS_IMPORT_MAX_NODES (1u << 20)
// The import itself runs in a child process (rs_import_load): at most this much address space and CPU.
#define RS_IMPORT_MAX_MEMORY ((uint64_t)8 << 30)
#define RS_IMPORT_MAX_CPU_SECONDS 600
// Texture limits, checked from the image header before any pixel is allocated: a side of at most
// RS_IMAGE_MAX_DIM and at most 64 Mpx (an 8K x 8K page, 192 MiB as RGB).
#define RS_IMPORT_MAX_TEXTURE_PIXELS ((uint64_t)8192 * 8192)

typedef enum rs_import_format {
    RS_IMPORT_PLY,
    RS_IMPORT_OBJ,
    RS_IMPORT_GLTF,   // .gltf or .glb
    RS_IMPORT_FBX,
    RS_IMPORT_DAE,
    RS_IMPORT_STL,
    RS_IMPORT_OTHER,  // any other format assimp reads
} rs_import_format;

// One material: where its base-colour texture comes from (neither: the page has no texture).
typedef struct rs_import_page {
    char name[64];          // material name, for messages (sanitised when printed)
    char *texture;          // the path as the file names it (relative to the model's folder), or NULL
    const uint8_t *embedded;  // the image file's bytes when the model embeds it (GLB, FBX), or NULL
    size_t embedded_len;
    // An embedded image handed over as raw texels (assimp's aiTexel, B G R A per pixel) rather than a
    // file: its size (then embedded_len == 4 * raw_width * raw_height); 0 for an image file.
    uint32_t raw_width, raw_height;
    // How texture coordinates outside [0, 1] read the image along u and v (rs_pack_wrap in pack.h):
    // repeat unless the material says otherwise (AI_MATKEY_MAPPINGMODE_U / _V).
    uint8_t wrap[2];
    uint8_t *embedded_copy;   // what `embedded` points to when the import ran in a child process
} rs_import_page;

// Options of rs_import_load_with; zero is the default.
typedef struct rs_import_desc {
    // Files a model names (MTL, glTF buffers, textures) are read only from the model's folder and below
    // (after symlinks are resolved): a model cannot make rouge-pack read /etc/passwd or ../../secret.
    // True allows any path (rouge-pack --allow-outside-paths).
    bool allow_outside_paths;
    // Read in this process, without the child process and its limits (tests).
    bool in_process;
} rs_import_desc;

typedef struct rs_import_scene {
    rs_ply_mesh *mesh;          // the geometry; mesh->tri_page is set when there is more than one page
    rs_import_format format;
    char format_name[64];       // "glTF 2.0 (binary)", "Wavefront OBJ", ... for the summary
    char path[4096];            // the model file, to resolve texture paths
    // The unit the file declares, as millimetres per model unit (0 = the format has none, e.g. OBJ, STL),
    // and where it came from ("glTF: metres by definition").
    float declared_mm_per_unit;
    char unit_source[96];
    // glTF's texture origin is the top-left corner; assimp flips v so that every format's UVs follow the
    // OpenGL convention (t = 0 is the bottom row). True when that flip was applied, so a texture given
    // on the command line (not named by the file) can be sampled with the file's own coordinates.
    bool v_flipped;
    uint32_t page_count;
    rs_import_page *pages;      // page_count entries (NULL when 0)
    uint32_t points_dropped;    // point and line primitives of a mesh that also has triangles
    bool allow_outside_paths;   // from rs_import_desc: textures may come from anywhere
    void *priv;                 // assimp's scene (embedded images point into it), or NULL
} rs_import_scene;

// Reads any supported model (see above). Errors: one line naming the file; a file that neither the PLY
// reader nor assimp can read says which formats are supported. A file the model names that is missing
// (an OBJ's MTL) is a warning in mesh->warnings; one that is not a regular file, or lies outside the
// model's folder (see rs_import_desc), is an error that names it and never quotes its bytes.
// Hostile files: rs_import_guard runs first; then assimp reads the file in a child process limited to
// RS_IMPORT_MAX_MEMORY of address space and RS_IMPORT_MAX_CPU_SECONDS, which flattens the scene and sends
// the mesh back through a pipe, so a crash (stack overflow) or a memory bomb inside assimp is an error
// naming the file, not the end of rouge-pack.
rs_result rs_import_load(const char *path, rs_import_scene **out, rs_error *err);
rs_result rs_import_load_with(const char *path, const rs_import_desc *desc, rs_import_scene **out, rs_error *err);
// Same, from memory (the fuzz harness): `hint` is the file extension ("obj", "glb"); materials can name
// no external files here.
rs_result rs_import_load_memory(const void *data, size_t len, const char *hint, rs_import_scene **out,
                                rs_error *err);
void rs_import_destroy(rs_import_scene *s);

// import_guard.c: checks a model's bytes before assimp reads them, without recursion: nesting of XML
// elements, JSON containers and FBX records (at most RS_IMPORT_MAX_DEPTH), the node graphs of glTF and
// COLLADA (no node containing itself, at most RS_IMPORT_MAX_DEPTH deep, unrolling to at most
// RS_IMPORT_MAX_NODES), and FBX arrays claiming more bytes than their stored bytes can inflate to.
// RS_ERR_LIMIT / RS_ERR_FORMAT with one line naming `name`; a file it cannot parse passes (assimp refuses it).
rs_result rs_import_guard(const void *data, size_t len, rs_import_format format, const char *name, rs_error *err);
const char *rs_import_format_name(rs_import_format f);

// Decodes every page's texture (embedded bytes, or the file named relative to the model's folder) into
// *out (page_count images; a page without a texture stays zeroed). A texture never stops a conversion:
// one that is missing, refused by the path policy, unreadable or in an unsupported format leaves its page
// zeroed (the sampler falls back to vertex colours or the default grey) and adds a warning naming the
// material and the file to warnings[cap] ("; "-joined). Errors: out of memory only.
// Texture paths: Windows separators and drive letters are accepted ("C:\x\skin.png", "\tex\skin.png"
// name skin.png, looked for as given below the model's folder, then by its bare name there).
rs_result rs_import_load_pages(const rs_import_scene *s, rs_image **out, char *warnings, size_t cap, rs_error *err);
void rs_import_free_pages(rs_image *pages, uint32_t count);

// Texture images (image_load.c): PNG (libpng, src/core/image.c), JPEG (libjpeg-turbo: baseline and
// progressive), BMP or TGA (stb_image), by content. The size
// the header claims is checked (sides, RS_IMPORT_MAX_TEXTURE_PIXELS, and what the file's bytes can encode)
// before pixels are allocated. `name` is used in messages.
rs_result rs_image_load_any(const char *path, rs_image *out, rs_error *err);
// The same for a file the user did not name (a model's texture): errors never quote its bytes.
rs_result rs_image_load_referenced(const char *path, rs_image *out, rs_error *err);
rs_result rs_image_decode_any(const void *data, size_t len, const char *name, rs_image *out, rs_error *err);

#endif
