// make_import_fixtures.c — writes the import fixtures that need more than Python's standard library:
// the small OBJ + MTL + JPEG export of the Lee Perry-Smith head (tests/fixtures/import/head/) and the
// JPEG test images (tests/fixtures/import/*.jpg). `make import-fixtures` builds and runs it; the output is
// committed, so tests never need ../shared/data for these.
//
// The head: ../shared/data/leeperrysmith/head_mesh.ply (the GLB's own vertices, UVs and triangles) is
// decimated by vertex clustering inside each UV island (a cluster per grid cell of CELL units, island and
// dominant normal axis, at the mean position and UV of its vertices; triangles whose corners fall into
// fewer than three clusters vanish), so the islands and their seams stay as in the source; color.png is box-filtered to
// 512 x 512 and saved as a JPEG. The MTL names it with spaces in the file name, as photogrammetry tools
// often do. CC BY 3.0: the attribution goes into the OBJ's header comments and the folder's README.md.
#define _POSIX_C_SOURCE 200809L
#include "core/image.h"
#include "pack/ply.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STBI_WRITE_NO_STDIO
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wimplicit-fallthrough"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#include <stb_image_write.h>
#pragma GCC diagnostic pop

#define CELL 0.24f          // model units (the head is ~8 units wide; source median edge 0.064)
#define TEXTURE_PX 512
#define JPEG_QUALITY 88
#define TEXTURE_NAME "Lee Perry-Smith colour.jpg"

static const char attribution[] =
    "Infinite, 3D Head Scan by Lee Perry-Smith is licensed under a Creative Commons Attribution 3.0 Unported\n"
    "License (https://creativecommons.org/licenses/by/3.0/). Based on a work at www.triplegangers.com.\n"
    "Obtained from the three.js examples (https://github.com/mrdoob/three.js, examples/models/gltf/LeePerrySmith/);\n"
    "decimated to an OBJ + MTL + JPEG export for rouge's tests by tools/make_import_fixtures.c.\n";

typedef struct buf {
    uint8_t *d;
    size_t n, cap;
} buf;

static void buf_put(void *ctx, void *data, int size)
{
    buf *b = ctx;
    if (b->n + (size_t)size > b->cap) {
        b->cap = (b->n + (size_t)size) * 2;
        b->d = realloc(b->d, b->cap);
        if (!b->d) exit(1);
    }
    memcpy(b->d + b->n, data, (size_t)size);
    b->n += (size_t)size;
}

static int write_file(const char *path, const void *d, size_t n)
{
    rs_error err = {0};
    if (rs_file_write_atomic(path, d, n, &err) != RS_OK) {
        fprintf(stderr, "make_import_fixtures: %s\n", err.msg);
        return 1;
    }
    printf("wrote %s (%zu bytes)\n", path, n);
    return 0;
}

static int write_jpeg(const char *path, int w, int h, const uint8_t *rgb, int quality)
{
    buf b = {0};
    if (!stbi_write_jpg_to_func(buf_put, &b, w, h, 3, rgb, quality)) return 1;
    int r = write_file(path, b.d, b.n);
    free(b.d);
    return r;
}

static uint32_t uf_find(uint32_t *p, uint32_t x)
{
    while (p[x] != x) x = p[x] = p[p[x]];
    return x;
}

typedef struct key {
    uint32_t island, facing;
    int32_t c[3];
    uint32_t id;
} key;

static int cmp_key(const void *a, const void *b)
{
    const key *x = a, *y = b;
    if (x->island != y->island) return x->island < y->island ? -1 : 1;
    if (x->facing != y->facing) return x->facing < y->facing ? -1 : 1;
    for (int k = 0; k < 3; k++)
        if (x->c[k] != y->c[k]) return x->c[k] < y->c[k] ? -1 : 1;
    return (x->id > y->id) - (x->id < y->id);
}

typedef struct tkey {
    uint32_t s[3], c[3], t;  // sorted corners (the identity), corners in the source's order, source index
} tkey;

static int cmp_tkey(const void *a, const void *b)
{
    const tkey *x = a, *y = b;
    for (int k = 0; k < 3; k++)
        if (x->s[k] != y->s[k]) return x->s[k] < y->s[k] ? -1 : 1;
    return (x->t > y->t) - (x->t < y->t);
}

static int head(const char *data, const char *out)
{
    char path[1024];
    rs_error err = {0};
    rs_ply_mesh *m = NULL;
    snprintf(path, sizeof path, "%s/head_mesh.ply", data);
    if (rs_ply_load(path, &m, &err) != RS_OK) return fprintf(stderr, "make_import_fixtures: %s\n", err.msg), 1;
    uint32_t n = m->vertex_count;
    // UV islands = connected components of the index graph (the source splits vertices along seams).
    uint32_t *parent = malloc(n * sizeof *parent), *cluster = malloc(n * sizeof *cluster);
    key *k = malloc(n * sizeof *k);
    for (uint32_t v = 0; v < n; v++) parent[v] = v;
    for (uint32_t t = 0; t < m->tri_count; t++)
        for (int e = 1; e < 3; e++) {
            uint32_t a = uf_find(parent, m->tri[t][0]), b = uf_find(parent, m->tri[t][e]);
            if (a != b) parent[a] = b;
        }
    for (uint32_t v = 0; v < n; v++) {
        k[v].island = uf_find(parent, v);
        // The dominant axis of the normal (6 classes) keeps sheets that face each other apart: the
        // closed lips and eyelids lie closer than a cell.
        int ax = 0;
        for (int a = 1; a < 3; a++)
            if (fabsf(m->normal[v][a]) > fabsf(m->normal[v][ax])) ax = a;
        k[v].facing = (uint32_t)(2 * ax + (m->normal[v][ax] < 0));
        for (int a = 0; a < 3; a++) k[v].c[a] = (int32_t)floorf(m->pos[v][a] / CELL);
        k[v].id = v;
    }
    qsort(k, n, sizeof *k, cmp_key);
    uint32_t nc = 0;
    for (uint32_t i = 0; i < n; i++) {
        bool same = i > 0 && k[i].island == k[i - 1].island && k[i].facing == k[i - 1].facing &&
                    !memcmp(k[i].c, k[i - 1].c, sizeof k[i].c);
        cluster[k[i].id] = same ? cluster[k[i - 1].id] : nc++;
    }
    double(*sum)[6] = calloc(nc, sizeof *sum);
    uint32_t *cnt = calloc(nc, sizeof *cnt);
    for (uint32_t v = 0; v < n; v++) {
        double *s = sum[cluster[v]];
        for (int a = 0; a < 3; a++) s[a] += m->pos[v][a];
        s[3] += m->uv[v][0];
        s[4] += m->uv[v][1];
        cnt[cluster[v]]++;
    }
    buf obj = {0};
    char line[256];
#define PUT(...) buf_put(&obj, line, snprintf(line, sizeof line, __VA_ARGS__))
    for (const char *s = attribution; *s;) {
        const char *e = strchr(s, '\n');
        PUT("# %.*s\n", (int)(e - s), s);
        s = e + 1;
    }
    PUT("mtllib head.mtl\n");
    for (uint32_t c = 0; c < nc; c++) PUT("v %.4f %.4f %.4f\n", sum[c][0] / cnt[c], sum[c][1] / cnt[c], sum[c][2] / cnt[c]);
    for (uint32_t c = 0; c < nc; c++) PUT("vt %.4f %.4f\n", sum[c][3] / cnt[c], sum[c][4] / cnt[c]);
    PUT("usemtl skin\n");
    // Each surviving triangle once: clusters can map several source triangles onto the same corners.
    tkey *tk = malloc(m->tri_count * sizeof *tk);
    uint32_t nt = 0, kept = 0;
    for (uint32_t t = 0; t < m->tri_count; t++) {
        uint32_t c3[3] = {cluster[m->tri[t][0]], cluster[m->tri[t][1]], cluster[m->tri[t][2]]};
        if (c3[0] == c3[1] || c3[1] == c3[2] || c3[0] == c3[2]) continue;
        memcpy(tk[nt].c, c3, sizeof c3);
        memcpy(tk[nt].s, c3, sizeof c3);
        for (int i = 0; i < 2; i++)
            for (int j = 0; j < 2 - i; j++)
                if (tk[nt].s[j] > tk[nt].s[j + 1]) {
                    uint32_t x = tk[nt].s[j];
                    tk[nt].s[j] = tk[nt].s[j + 1], tk[nt].s[j + 1] = x;
                }
        tk[nt].t = t;
        nt++;
    }
    qsort(tk, nt, sizeof *tk, cmp_tkey);
    for (uint32_t i = 0; i < nt; i++) {
        if (i > 0 && !memcmp(tk[i].s, tk[i - 1].s, sizeof tk[i].s)) continue;
        PUT("f %u/%u %u/%u %u/%u\n", tk[i].c[0] + 1, tk[i].c[0] + 1, tk[i].c[1] + 1, tk[i].c[1] + 1, tk[i].c[2] + 1, tk[i].c[2] + 1);
        kept++;
    }
    free(tk);
#undef PUT
    int r = 0;
    snprintf(path, sizeof path, "%s/head.obj", out);
    r |= write_file(path, obj.d, obj.n);
    printf("  %u vertices, %u triangles (source %u, %u)\n", nc, kept, n, m->tri_count);
    const char mtl[] = "# the colour map of the Lee Perry-Smith scan (CC BY 3.0, see README.md)\n"
                       "newmtl skin\nKd 1 1 1\nmap_Kd " TEXTURE_NAME "\n";
    snprintf(path, sizeof path, "%s/head.mtl", out);
    r |= write_file(path, mtl, sizeof mtl - 1);

    rs_image col = {0};
    snprintf(path, sizeof path, "%s/color.png", data);
    if (rs_image_read_png(path, &col, &err) != RS_OK) return fprintf(stderr, "make_import_fixtures: %s\n", err.msg), 1;
    int f = col.width / TEXTURE_PX;
    uint8_t *small = malloc((size_t)TEXTURE_PX * TEXTURE_PX * 3);
    for (int y = 0; y < TEXTURE_PX; y++)
        for (int x = 0; x < TEXTURE_PX; x++)
            for (int c = 0; c < 3; c++) {
                int s = 0;
                for (int dy = 0; dy < f; dy++)
                    for (int dx = 0; dx < f; dx++)
                        s += col.pixels[((size_t)(y * f + dy) * col.width + (size_t)(x * f + dx)) * col.channels + c];
                small[((size_t)y * TEXTURE_PX + x) * 3 + c] = (uint8_t)((s + f * f / 2) / (f * f));
            }
    snprintf(path, sizeof path, "%s/%s", out, TEXTURE_NAME);
    r |= write_jpeg(path, TEXTURE_PX, TEXTURE_PX, small, JPEG_QUALITY);
    free(small), rs_image_free(&col), free(obj.d), free(sum), free(cnt), free(k), free(cluster), free(parent);
    rs_ply_destroy(m);
    return r;
}

// Small JPEGs for tests/test_import.c: a colour page, a truncated copy, a header claiming 16000 x 16000
// pixels (past the 64 Mpx cap) and one claiming 8000 x 8000 in a few hundred bytes (a bomb).
static int jpegs(const char *out)
{
    uint8_t px[16 * 16 * 3];
    for (int i = 0; i < 16 * 16; i++) px[3 * i] = 240, px[3 * i + 1] = 200, px[3 * i + 2] = 20;
    buf b = {0};
    if (!stbi_write_jpg_to_func(buf_put, &b, 16, 16, 3, px, 95)) return 1;
    char path[1024];
    int r = 0;
    snprintf(path, sizeof path, "%s/yellow 16.jpg", out);
    r |= write_file(path, b.d, b.n);
    snprintf(path, sizeof path, "%s/bad_truncated.jpg", out);
    r |= write_file(path, b.d, b.n / 2);
    // The SOF0 frame header: FF C0, length, precision, then height and width (big-endian).
    for (size_t i = 0; i + 9 < b.n; i++)
        if (b.d[i] == 0xff && b.d[i + 1] == 0xc0) {
            uint8_t *hw = b.d + i + 5;
            hw[0] = 16000 >> 8, hw[1] = 16000 & 255, hw[2] = 16000 >> 8, hw[3] = 16000 & 255;
            snprintf(path, sizeof path, "%s/bad_huge.jpg", out);
            r |= write_file(path, b.d, b.n);
            hw[0] = 8000 >> 8, hw[1] = 8000 & 255, hw[2] = 8000 >> 8, hw[3] = 8000 & 255;
            snprintf(path, sizeof path, "%s/bad_bomb.jpg", out);
            r |= write_file(path, b.d, b.n);
            break;
        }
    free(b.d);
    return r;
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: make_import_fixtures SHARED_DATA_DIR/leeperrysmith OUT_DIR (tests/fixtures/import)\n");
        return 2;
    }
    char head_dir[1024];
    snprintf(head_dir, sizeof head_dir, "%s/head", argv[2]);
    return head(argv[1], head_dir) | jpegs(argv[2]);
}
