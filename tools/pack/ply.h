// ply.h — a hardened reader for PLY files (ASCII, binary little- and big-endian), used by rouge-pack.
//
// Does: parse the header (any property order; char/uchar/short/ushort/int/uint/float/double and their
// int8/uint8/... aliases; list properties), read `vertex` positions, normals (nx ny nz), colours
// (red green blue or diffuse_red..., uchar or float 0..1), texture coordinates (s t | u v |
// texture_u texture_v), an optional per-vertex `region` (uchar/int), and `face` lists (polygons are
// fan-triangulated). Unknown elements and properties are skipped. Every count is checked against the
// bytes that remain before anything is allocated, so allocations are capped by the file size.
// ASCII bodies are one record per line. Limits: header 64 KiB, header lines 4096 bytes, 64 elements,
// 512 properties. `tri` is NULL exactly when tri_count is 0 (faces with < 3 indices are skipped, but
// their indices are still validated). Numbers are parsed in the C locale (never set LC_NUMERIC).
// Does not: write PLY, or keep any property not listed above.
//
//   rs_ply_mesh *m = NULL;
//   if (rs_ply_load("head.ply", &m, &err) != RS_OK) { puts(err.msg); return 1; }
//   printf("%u vertices, %u triangles\n", m->vertex_count, m->tri_count);
//   rs_ply_destroy(m);
#ifndef RS_PLY_H
#define RS_PLY_H

#include "core/core.h"

#define RS_PLY_MAX_FILE ((size_t)2 << 30)  // 2 GiB

typedef struct rs_ply_mesh {
    uint32_t vertex_count;
    float (*pos)[3];
    float (*normal)[3];   // NULL when the file has no normals
    uint8_t (*rgb)[3];    // NULL when the file has no colours (float colours are scaled to 0..255)
    float (*uv)[2];       // NULL when the file has no texture coordinates
    uint8_t *region;      // NULL when the file has no per-vertex `region` property
    uint32_t tri_count;
    uint32_t (*tri)[3];   // NULL when the file has no faces; indices validated < vertex_count
    uint16_t *tri_page;   // texture page (material) per triangle, or NULL (all page 0): set by import.h
                          // for multi-material models, never by the PLY reader
    char *comments;       // header comments joined by '\n' (carries the CC-BY attribution), never NULL
    char *texture_file;   // from "comment TextureFile NAME" (MeshLab convention), or NULL
    char warnings[512];   // what was accepted though not by the letter of the format ("; "-joined), or ""
} rs_ply_mesh;

rs_result rs_ply_load(const char *path, rs_ply_mesh **out, rs_error *err);
// Errors name the element/property and the byte offset (or line for ASCII).
rs_result rs_ply_load_memory(const void *data, size_t len, rs_ply_mesh **out, rs_error *err);
void rs_ply_destroy(rs_ply_mesh *m);

#endif
