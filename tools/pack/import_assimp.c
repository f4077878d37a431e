// import_assimp.c — models through assimp (and PLY through ply.c) into one welded triangle mesh; see
// import.h.
//
// Why assimp: one maintained library (Debian's libassimp-dev, C API) reads the forty-odd formats scans come
// in, with their materials and node transforms. Why PLY stays ours: ply.c is faster on 600k-point clouds,
// keeps the `region` property and the header comments (attribution), and has been fuzzed and
// hardened; assimp's PLY reader drops point clouds' extra properties.
#define _XOPEN_SOURCE 700  // realpath
#include "pack/import.h"
#include "pack/pack.h"

#include <assimp/cfileio.h>
#include <assimp/cimport.h>
#include <assimp/material.h>
#include <assimp/metadata.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

const char *rs_import_format_name(rs_import_format f)
{
    static const char *names[] = {"PLY", "Wavefront OBJ", "glTF 2.0", "FBX", "COLLADA", "STL", "model"};
    return f <= RS_IMPORT_OTHER ? names[f] : "?";
}

// ---- file access for assimp: regular files only, size-capped, read whole into memory ----

typedef struct io_ctx {
    const char *mem_name;  // a file served from memory (rs_import_load_memory), or NULL
    const uint8_t *mem;
    size_t mem_len;
    bool disk;             // other files may be read from disk
    const char *main;      // the model itself: why opening it failed is the error to report
    rs_import_format format;
    bool allow_outside;    // files the model names may lie outside its folder
    char dir[4096];        // the model's folder, symlinks resolved
    char failed[512];      // why the model itself could not be read, or was refused (rs_import_guard)
    char refused[512];     // the first file the model names that was refused: an error
    char missing[512];     // the first file the model names that is not there: a warning
} io_ctx;

typedef struct io_file {
    const uint8_t *data;
    uint8_t *owned;
    size_t len, pos;
} io_file;

static size_t io_read(struct aiFile *f, char *buf, size_t size, size_t count)
{
    io_file *h = (io_file *)f->UserData;
    if (size == 0) return 0;
    size_t n = RS_MIN(count, (h->len - h->pos) / size);
    memcpy(buf, h->data + h->pos, n * size);
    h->pos += n * size;
    return n;
}

static size_t io_write(struct aiFile *f, const char *buf, size_t size, size_t count)
{
    (void)f, (void)buf, (void)size, (void)count;
    return 0;
}

static size_t io_tell(struct aiFile *f)
{
    return ((io_file *)f->UserData)->pos;
}

static size_t io_size(struct aiFile *f)
{
    return ((io_file *)f->UserData)->len;
}

static void io_flush(struct aiFile *f)
{
    (void)f;
}

static enum aiReturn io_seek(struct aiFile *f, size_t off, enum aiOrigin origin)
{
    io_file *h = (io_file *)f->UserData;
    size_t base = origin == aiOrigin_SET ? 0 : origin == aiOrigin_CUR ? h->pos : h->len;
    // assimp passes negative offsets as wrapped size_t: the sum wraps back, so compare the result.
    size_t to = base + off;
    if (to > h->len) return aiReturn_FAILURE;
    h->pos = to;
    return aiReturn_SUCCESS;
}

// Whether `path` (which exists) lies in the folder `dir` or below, symlinks resolved.
static bool inside_folder(const char *dir, const char *path)
{
    char real[PATH_MAX];
    if (!realpath(path, real)) return false;
    size_t n = strlen(dir);
    return !strcmp(dir, "/") || (!strncmp(real, dir, n) && real[n] == '/');
}

// The folder of `path` with symlinks resolved, into dir[cap] ("" when it cannot be resolved).
static void model_folder(const char *path, char *dir, size_t cap)
{
    char real[PATH_MAX];
    dir[0] = 0;
    if (!realpath(path, real)) return;
    char *slash = strrchr(real, '/');
    if (slash == real) slash[1] = 0;
    else if (slash) *slash = 0;
    snprintf(dir, cap, "%s", real);
}

// A file the model names (an MTL, a glTF buffer): missing is a warning (assimp goes on without it, and
// the summary says what was lost); outside the model's folder, or not a regular file, is refused.
static bool io_open_named(io_ctx *c, const char *path, void **data, size_t *len)
{
    // assimp's OBJ reader joins the model's folder and an absolute MTL path ("dir//dev/zero"): the file
    // the model names is the absolute one.
    const char *abs = strstr(path, "//");
    if (abs) path = abs + 1;
    struct stat st;
    if (stat(path, &st) != 0) {
        if (!c->missing[0]) snprintf(c->missing, sizeof c->missing, "it names '%s', which is not there (%s)", path, strerror(errno));
        return false;
    }
    if (!c->allow_outside && (!c->dir[0] || !inside_folder(c->dir, path))) {
        if (!c->refused[0])
            snprintf(c->refused, sizeof c->refused, "it names '%s', outside the model's folder: not read "
                                                    "(rouge-pack --allow-outside-paths reads it)", path);
        return false;
    }
    rs_error e = {0};
    if (rs_file_read_all(path, RS_IMPORT_MAX_FILE, data, len, &e) != RS_OK) {
        if (!c->refused[0]) snprintf(c->refused, sizeof c->refused, "a file it names: %s", e.msg);
        return false;
    }
    return true;
}

static struct aiFile *io_open(struct aiFileIO *io, const char *path, const char *mode)
{
    io_ctx *c = (io_ctx *)io->UserData;
    if (!path || !mode || strchr(mode, 'w') || strchr(mode, 'a') || strchr(mode, '+')) return NULL;
    bool is_main = c->main && !strcmp(path, c->main);
    // The model itself, refused once: assimp opens it again to try other readers.
    if (is_main && c->failed[0]) return NULL;
    io_file *h = calloc(1, sizeof *h);
    struct aiFile *f = calloc(1, sizeof *f);
    if (!h || !f) {
        free(h);
        free(f);
        return NULL;
    }
    rs_error e = {0};
    if (c->mem_name && !strcmp(path, c->mem_name)) {
        h->data = c->mem;
        h->len = c->mem_len;
    } else if (c->disk && is_main) {
        void *data;
        size_t len;
        if (rs_file_read_all(path, RS_IMPORT_MAX_FILE, &data, &len, &e) != RS_OK) {
            snprintf(c->failed, sizeof c->failed, "%s", e.msg);
            free(h);
            free(f);
            return NULL;
        }
        h->data = h->owned = data;
        h->len = len;
    } else if (c->disk) {
        void *data;
        size_t len;
        if (!io_open_named(c, path, &data, &len)) {
            free(h);
            free(f);
            return NULL;
        }
        h->data = h->owned = data;
        h->len = len;
    } else {
        free(h);
        free(f);
        return NULL;
    }
    // What assimp would recurse into or inflate without bound is refused before it reads a byte.
    if (is_main && rs_import_guard(h->data, h->len, c->format, path, &e) != RS_OK) {
        snprintf(c->failed, sizeof c->failed, "%s", e.msg);
        free(h->owned);
        free(h);
        free(f);
        return NULL;
    }
    *f = (struct aiFile){.ReadProc = io_read, .WriteProc = io_write, .TellProc = io_tell, .FileSizeProc = io_size,
                         .SeekProc = io_seek, .FlushProc = io_flush, .UserData = (aiUserData)h};
    return f;
}

static void io_close(struct aiFileIO *io, struct aiFile *f)
{
    (void)io;
    if (!f) return;
    io_file *h = (io_file *)f->UserData;
    free(h->owned);
    free(h);
    free(f);
}

// ---- format sniffing ----

static const char *ext_of(const char *path)
{
    const char *slash = strrchr(path, '/'), *dot = strrchr(path, '.');
    return dot && (!slash || dot > slash) ? dot + 1 : "";
}

static bool is_ply_magic(const uint8_t *d, size_t n)
{
    if (n >= 3 && d[0] == 0xef && d[1] == 0xbb && d[2] == 0xbf) d += 3, n -= 3;  // UTF-8 BOM (ply.c accepts it)
    return n >= 4 && !memcmp(d, "ply", 3) && (d[3] == '\n' || d[3] == '\r');
}

static bool contains(const uint8_t *d, size_t n, const char *s)
{
    size_t k = strlen(s);
    for (size_t i = 0; i + k <= n; i++)
        if (!memcmp(d + i, s, k)) return true;
    return false;
}

static rs_import_format sniff(const uint8_t *d, size_t n, const char *ext)
{
    if (n >= 4 && !memcmp(d, "glTF", 4)) return RS_IMPORT_GLTF;
    if (n >= 18 && !memcmp(d, "Kaydara FBX Binary", 18)) return RS_IMPORT_FBX;
    if (!strcasecmp(ext, "gltf") || !strcasecmp(ext, "glb")) return RS_IMPORT_GLTF;
    if (!strcasecmp(ext, "fbx")) return RS_IMPORT_FBX;
    if (!strcasecmp(ext, "dae") || contains(d, n, "<COLLADA")) return RS_IMPORT_DAE;
    if (!strcasecmp(ext, "stl")) return RS_IMPORT_STL;
    if (!strcasecmp(ext, "obj")) return RS_IMPORT_OBJ;
    return RS_IMPORT_OTHER;
}

// ---- flattening ----

static float meta_number(const struct aiMetadata *m, const char *key, bool *found)
{
    *found = false;
    for (unsigned i = 0; m && i < m->mNumProperties; i++) {
        if (strcmp(m->mKeys[i].data, key) || !m->mValues[i].mData) continue;
        const struct aiMetadataEntry *e = &m->mValues[i];
        *found = true;
        switch (e->mType) {
        case AI_FLOAT: return *(const float *)e->mData;
        case AI_DOUBLE: return (float)*(const double *)e->mData;
        case AI_INT32: return (float)*(const int32_t *)e->mData;
        default: *found = false; return 0;
        }
    }
    return 0;
}

static const char *meta_string(const struct aiMetadata *m, const char *key)
{
    for (unsigned i = 0; m && i < m->mNumProperties; i++)
        if (!strcmp(m->mKeys[i].data, key) && m->mValues[i].mType == AI_AISTRING && m->mValues[i].mData)
            return ((const struct aiString *)m->mValues[i].mData)->data;
    return NULL;
}

typedef struct weld_key {
    uint32_t page;
    uint32_t bits[5];  // position and UV bit patterns (exact matches only)
    uint32_t id;
} weld_key;

static int cmp_weld(const void *a, const void *b)
{
    const weld_key *x = a, *y = b;
    if (x->page != y->page) return x->page < y->page ? -1 : 1;
    for (int k = 0; k < 5; k++)
        if (x->bits[k] != y->bits[k]) return x->bits[k] < y->bits[k] ? -1 : 1;
    return (x->id > y->id) - (x->id < y->id);
}

static uint32_t float_bits(float f)
{
    uint32_t u;
    if (f == 0) f = 0;  // -0 and +0 weld
    memcpy(&u, &f, 4);
    return u;
}

// Merges vertices with the same page, position and UV (OBJ gives every face corner its own vertex;
// flat-shaded files split every corner by normal). Normals of merged vertices are summed (the sampler
// normalises them), so a flat-shaded scan is shaded smoothly; UV seams stay split as in the file.
static rs_result weld(rs_ply_mesh *m, const uint32_t *vpage, rs_error *err)
{
    uint32_t n = m->vertex_count;
    weld_key *k = rs_alloc_array(n, sizeof *k);
    uint32_t *remap = rs_alloc_array(n, sizeof *remap);
    if (!k || !remap) {
        free(k);
        free(remap);
        return rs_fail(err, RS_ERR_NOMEM, "out of memory welding %u vertices", n);
    }
    for (uint32_t i = 0; i < n; i++) {
        k[i].page = vpage[i];
        for (int a = 0; a < 3; a++) k[i].bits[a] = float_bits(m->pos[i][a]);
        k[i].bits[3] = m->uv ? float_bits(m->uv[i][0]) : 0;
        k[i].bits[4] = m->uv ? float_bits(m->uv[i][1]) : 0;
        k[i].id = i;
    }
    qsort(k, n, sizeof *k, cmp_weld);
    uint32_t out = 0;
    for (uint32_t i = 0; i < n; i++) {
        bool same = i > 0 && k[i].page == k[i - 1].page && !memcmp(k[i].bits, k[i - 1].bits, sizeof k[i].bits);
        remap[k[i].id] = same ? remap[k[i - 1].id] : out++;
    }
    // Compact into fresh arrays (in place would overwrite unread vertices).
    float(*pos)[3] = rs_alloc_array(out, sizeof *pos);
    float(*nrm)[3] = m->normal ? calloc(out, sizeof *nrm) : NULL;
    float(*uv)[2] = m->uv ? rs_alloc_array(out, sizeof *uv) : NULL;
    uint8_t(*rgb)[3] = m->rgb ? rs_alloc_array(out, sizeof *rgb) : NULL;
    if (!pos || (m->normal && !nrm) || (m->uv && !uv) || (m->rgb && !rgb)) {
        free(k), free(remap), free(pos), free(nrm), free(uv), free(rgb);
        return rs_fail(err, RS_ERR_NOMEM, "out of memory welding %u vertices", n);
    }
    for (uint32_t i = 0; i < n; i++) {
        uint32_t j = remap[i];
        memcpy(pos[j], m->pos[i], sizeof pos[j]);
        if (uv) memcpy(uv[j], m->uv[i], sizeof uv[j]);
        if (rgb) memcpy(rgb[j], m->rgb[i], sizeof rgb[j]);
        if (nrm)
            for (int a = 0; a < 3; a++) nrm[j][a] += isfinite(m->normal[i][a]) ? m->normal[i][a] : 0;
    }
    for (uint32_t t = 0; t < m->tri_count; t++)
        for (int c = 0; c < 3; c++) m->tri[t][c] = remap[m->tri[t][c]];
    free(m->pos), free(m->normal), free(m->uv), free(m->rgb);
    m->pos = pos, m->normal = nrm, m->uv = uv, m->rgb = rgb;
    m->vertex_count = out;
    free(k);
    free(remap);
    return RS_OK;
}

static uint8_t to_u8(float v)
{
    return (uint8_t)lrintf(RS_CLAMP(isfinite(v) ? v : 0.0f, 0.0f, 1.0f) * 255.0f);
}

// Vertex colours: glTF's COLOR_0 is linear by definition, the other formats carry what the scanner
// wrote, which is sRGB (as in PLY).
static void colour_to_srgb8(const struct aiColor4D *c, bool linear, uint8_t out[3])
{
    float v[3] = {c->r, c->g, c->b};
    for (int a = 0; a < 3; a++) out[a] = to_u8(linear ? rs_linear_to_srgb(RS_CLAMP(isfinite(v[a]) ? v[a] : 0, 0, 1)) : v[a]);
}

static bool is_tri_mesh(const struct aiMesh *am)
{
    return (am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) && am->mNumFaces > 0 && am->mVertices;
}

// One mesh from every triangle mesh of the scene (node transforms already applied by assimp); a scene
// with no triangles but points becomes a point cloud.
static rs_result flatten(const struct aiScene *sc, rs_import_scene *s, rs_error *err)
{
    uint64_t nv = 0, nt = 0;
    bool any_tri = false, all_normals = true, any_uv = false, any_rgb = false;
    for (unsigned i = 0; i < sc->mNumMeshes; i++)
        any_tri |= sc->mMeshes[i] && is_tri_mesh(sc->mMeshes[i]);
    for (unsigned i = 0; i < sc->mNumMeshes; i++) {
        const struct aiMesh *am = sc->mMeshes[i];
        if (!am || !am->mVertices) continue;
        if (any_tri && !is_tri_mesh(am)) {
            s->points_dropped += am->mNumVertices;
            continue;
        }
        nv += am->mNumVertices;
        nt += any_tri ? am->mNumFaces : 0;
        all_normals &= am->mNormals != NULL;
        any_uv |= am->mTextureCoords[0] != NULL && am->mNumUVComponents[0] >= 2;
        any_rgb |= am->mColors[0] != NULL;
    }
    if (nv == 0) return rs_fail(err, RS_ERR_FORMAT, "%s: no geometry (no triangles or points) in the file", s->path);
    if (nv > RS_IMPORT_MAX_VERTICES || nt > RS_IMPORT_MAX_TRIANGLES)
        return rs_fail(err, RS_ERR_LIMIT, "%s: %llu vertices and %llu triangles, more than the %u and %u allowed", s->path,
                       (unsigned long long)nv, (unsigned long long)nt, RS_IMPORT_MAX_VERTICES, RS_IMPORT_MAX_TRIANGLES);
    if (sc->mNumMaterials > RS_IMPORT_MAX_PAGES)
        return rs_fail(err, RS_ERR_LIMIT, "%s: %u materials, more than the %d allowed", s->path, sc->mNumMaterials, RS_IMPORT_MAX_PAGES);

    rs_ply_mesh *m = calloc(1, sizeof *m);
    if (!m) return rs_fail(err, RS_ERR_NOMEM, "out of memory");
    s->mesh = m;
    m->comments = calloc(1, 1);
    m->pos = rs_alloc_array(nv, sizeof *m->pos);
    m->normal = all_normals ? rs_alloc_array(nv, sizeof *m->normal) : NULL;
    m->uv = any_uv ? rs_alloc_array(nv, sizeof *m->uv) : NULL;
    m->rgb = any_rgb ? rs_alloc_array(nv, sizeof *m->rgb) : NULL;
    m->tri = nt ? rs_alloc_array(nt, sizeof *m->tri) : NULL;
    uint16_t *tpage = nt ? rs_alloc_array(nt, sizeof *tpage) : NULL;
    uint32_t *vpage = rs_alloc_array(nv, sizeof *vpage);
    if (!m->comments || !m->pos || (all_normals && !m->normal) || (any_uv && !m->uv) || (any_rgb && !m->rgb) ||
        (nt && (!m->tri || !tpage)) || !vpage) {
        free(tpage);
        free(vpage);
        return rs_fail(err, RS_ERR_NOMEM, "%s: out of memory for %llu vertices", s->path, (unsigned long long)nv);
    }
    bool linear = s->format == RS_IMPORT_GLTF;
    uint32_t v0 = 0, t0 = 0;
    for (unsigned i = 0; i < sc->mNumMeshes; i++) {
        const struct aiMesh *am = sc->mMeshes[i];
        if (!am || !am->mVertices || (any_tri && !is_tri_mesh(am))) continue;
        uint32_t page = am->mMaterialIndex < sc->mNumMaterials ? am->mMaterialIndex : 0;
        for (unsigned v = 0; v < am->mNumVertices; v++) {
            uint32_t j = v0 + v;
            m->pos[j][0] = am->mVertices[v].x, m->pos[j][1] = am->mVertices[v].y, m->pos[j][2] = am->mVertices[v].z;
            if (m->normal)
                m->normal[j][0] = am->mNormals[v].x, m->normal[j][1] = am->mNormals[v].y, m->normal[j][2] = am->mNormals[v].z;
            if (m->uv) {
                bool has = am->mTextureCoords[0] && am->mNumUVComponents[0] >= 2;
                m->uv[j][0] = has ? am->mTextureCoords[0][v].x : 0;
                m->uv[j][1] = has ? am->mTextureCoords[0][v].y : 0;
            }
            if (m->rgb) {
                if (am->mColors[0]) colour_to_srgb8(&am->mColors[0][v], linear, m->rgb[j]);
                else m->rgb[j][0] = 200, m->rgb[j][1] = 178, m->rgb[j][2] = 160;
            }
            vpage[j] = page;
        }
        for (unsigned f = 0; any_tri && f < am->mNumFaces; f++) {
            const struct aiFace *fc = &am->mFaces[f];
            if (fc->mNumIndices != 3 || !fc->mIndices) continue;  // points or lines inside a triangle mesh
            bool ok = true;
            for (int c = 0; c < 3; c++) ok &= fc->mIndices[c] < am->mNumVertices;
            if (!ok)
                return free(tpage), free(vpage),
                       rs_fail(err, RS_ERR_FORMAT, "%s: mesh %u face %u: vertex index out of range", s->path, i, f);
            for (int c = 0; c < 3; c++) m->tri[t0][c] = v0 + fc->mIndices[c];
            tpage[t0++] = (uint16_t)page;
        }
        v0 += am->mNumVertices;
    }
    m->vertex_count = v0;
    m->tri_count = t0;
    if (t0 == 0) {
        free(m->tri);
        m->tri = NULL;
        free(tpage);
        tpage = NULL;
    }
    rs_result r = RS_OK;
    if (m->tri) r = weld(m, vpage, err);
    free(vpage);
    if (r != RS_OK) {
        free(tpage);
        return r;
    }
    if (sc->mNumMaterials > 1 && tpage) m->tri_page = tpage;
    else free(tpage);
    return RS_OK;
}

static void add_warning(rs_ply_mesh *m, const char *w);

// The file name after the last '/' or '\\' (models made on Windows use either).
static const char *base_name(const char *path)
{
    const char *b = path;
    for (const char *c = path; *c; c++)
        if (*c == '/' || *c == '\\') b = c + 1;
    return b;
}

// Base-colour texture of each material: glTF's baseColorTexture, else the diffuse map (MTL map_Kd, FBX,
// DAE); embedded images ("*N", or a file name matching an embedded texture's) point into the scene.
static rs_result collect_pages(const struct aiScene *sc, rs_import_scene *s, rs_error *err)
{
    s->page_count = sc->mNumMaterials;
    if (!s->page_count) return RS_OK;
    s->pages = calloc(s->page_count, sizeof *s->pages);
    if (!s->pages) return rs_fail(err, RS_ERR_NOMEM, "out of memory");
    for (uint32_t i = 0; i < s->page_count; i++) {
        const struct aiMaterial *mat = sc->mMaterials[i];
        rs_import_page *p = &s->pages[i];
        struct aiString name = {0};
        if (mat && aiGetMaterialString(mat, AI_MATKEY_NAME, &name) == aiReturn_SUCCESS)
            snprintf(p->name, sizeof p->name, "%.*s", (int)RS_MIN(name.length, sizeof p->name - 1), name.data);
        struct aiString path = {0};
        enum aiTextureMapMode mode[3] = {aiTextureMapMode_Wrap, aiTextureMapMode_Wrap, aiTextureMapMode_Wrap};
        bool have = false;
        enum aiTextureType types[2] = {aiTextureType_BASE_COLOR, aiTextureType_DIFFUSE};
        for (int k = 0; k < 2 && !have && mat; k++)
            have = aiGetMaterialTexture(mat, types[k], 0, &path, NULL, NULL, NULL, NULL, mode, NULL) == aiReturn_SUCCESS &&
                   path.length > 0 && path.length < sizeof path.data;
        if (!have) continue;
        // Decal (transparent outside [0, 1]) reads as clamp: a splat has no transparency.
        for (int a = 0; a < 2; a++)
            p->wrap[a] = mode[a] == aiTextureMapMode_Mirror ? RS_PACK_WRAP_MIRROR
                         : mode[a] == aiTextureMapMode_Clamp || mode[a] == aiTextureMapMode_Decal ? RS_PACK_WRAP_CLAMP
                                                                                                   : RS_PACK_WRAP_REPEAT;
        const struct aiTexture *tex = NULL;
        if (path.data[0] == '*') {
            char *end;
            long idx = strtol(path.data + 1, &end, 10);
            if (end == path.data + 1 || *end || idx < 0 || (unsigned long)idx >= sc->mNumTextures || !sc->mTextures[idx]) {
                // Not an error: the conversion goes on without this page's texture (see rs_import_load_pages).
                char w[160];
                snprintf(w, sizeof w, "material '%s' names embedded texture '%s', which does not exist: not textured",
                         p->name, path.data);
                add_warning(s->mesh, w);
                continue;
            }
            tex = sc->mTextures[idx];
        } else {
            // FBX embeds images under the file name its materials use (either separator).
            const char *want = base_name(path.data);
            for (unsigned t = 0; t < sc->mNumTextures && !tex; t++) {
                const struct aiTexture *c = sc->mTextures[t];
                if (c && c->mFilename.length && !strcmp(base_name(c->mFilename.data), want)) tex = c;
            }
        }
        if (tex && tex->pcData) {
            // Compressed (an image file's bytes, mWidth of them) or raw aiTexel rows (mWidth x mHeight).
            uint64_t len = tex->mHeight ? (uint64_t)tex->mWidth * tex->mHeight * sizeof(struct aiTexel) : tex->mWidth;
            if (tex->mHeight && (tex->mWidth > RS_IMAGE_MAX_DIM || tex->mHeight > RS_IMAGE_MAX_DIM)) {
                char w[160];
                snprintf(w, sizeof w, "material '%s': embedded texture of %ux%u texels, larger than the %d allowed: not textured",
                         p->name, tex->mWidth, tex->mHeight, RS_IMAGE_MAX_DIM);
                add_warning(s->mesh, w);
                continue;
            }
            p->embedded = (const uint8_t *)tex->pcData;
            p->embedded_len = (size_t)len;
            p->raw_width = tex->mHeight ? tex->mWidth : 0;
            p->raw_height = tex->mHeight;
        } else {
            p->texture = strdup(path.data);
            if (!p->texture) return rs_fail(err, RS_ERR_NOMEM, "out of memory");
        }
    }
    return RS_OK;
}

// The unit the format declares (after assimp's own conversions: COLLADA's <unit> is applied to the
// root node, FBX's UnitScaleFactor is not).
static void declared_unit(const struct aiScene *sc, rs_import_scene *s)
{
    bool found;
    switch (s->format) {
    case RS_IMPORT_GLTF:
        s->declared_mm_per_unit = 1000.0f;
        snprintf(s->unit_source, sizeof s->unit_source, "glTF: metres by definition");
        break;
    case RS_IMPORT_DAE:
        s->declared_mm_per_unit = 1000.0f;
        snprintf(s->unit_source, sizeof s->unit_source, "COLLADA <unit>, converted to metres by assimp");
        break;
    case RS_IMPORT_FBX: {
        float cm = meta_number(sc->mMetaData, "UnitScaleFactor", &found);
        if (found && cm > 0 && isfinite(cm) && cm < 1e6f) {
            s->declared_mm_per_unit = 10.0f * cm;
            snprintf(s->unit_source, sizeof s->unit_source, "FBX UnitScaleFactor %g (cm per unit)", cm);
        }
        break;
    }
    default: break;
    }
}

// The file's own leading comment lines (an OBJ's '#' header usually carries the author and licence),
// and glTF's asset copyright / generator, become the mesh comments (they go into the .rsf notes).
static void collect_comments(const struct aiScene *sc, const uint8_t *head, size_t n, rs_import_scene *s)
{
    char buf[1024];
    size_t len = 0;
    buf[0] = 0;
    if (s->format == RS_IMPORT_OBJ) {
        for (size_t i = 0; i < n && head[i] == '#';) {
            size_t e = i;
            while (e < n && head[e] != '\n') e++;
            size_t b = i + 1;
            while (b < e && (head[b] == ' ' || head[b] == '\t')) b++;
            size_t l = e - b;
            while (l && (head[b + l - 1] == '\r' || head[b + l - 1] == ' ')) l--;
            if (l && len + l + 2 < sizeof buf) {
                if (len) buf[len++] = '\n';
                memcpy(buf + len, head + b, l);
                len += l;
                buf[len] = 0;
            }
            i = e + 1;
        }
    }
    const char *keys[2] = {"SourceAsset_Copyright", "SourceAsset_Generator"};
    const char *labels[2] = {"copyright: ", "generator: "};
    for (int k = 0; k < 2; k++) {
        const char *v = meta_string(sc->mMetaData, keys[k]);
        if (v && *v) len += (size_t)snprintf(buf + len, sizeof buf - RS_MIN(len, sizeof buf - 1), "%s%s%s", len ? "\n" : "", labels[k], v);
        len = RS_MIN(len, sizeof buf - 1);
    }
    if (len) {
        char *c = strdup(buf);
        if (c) {
            free(s->mesh->comments);
            s->mesh->comments = c;
        }
    }
}

// Before PreTransformVertices copies every mesh once per node that instances it (10^4 nodes instancing
// one 10^4-triangle mesh become 10^8 triangles, 6.8 GB): the tree is walked without recursion, its depth
// and the triangles and vertices it unrolls to checked against the limits.
static rs_result check_unrolled(const struct aiScene *sc, const rs_import_scene *s, rs_error *err)
{
    if (!sc->mRootNode) return RS_OK;
    uint64_t *tris = calloc(sc->mNumMeshes + 1, sizeof *tris);
    size_t cap = 256, top = 0;
    struct item {
        const struct aiNode *node;
        uint32_t depth;
    } *stack = malloc(cap * sizeof *stack);
    if (!tris || !stack) {
        free(tris), free(stack);
        return rs_fail(err, RS_ERR_NOMEM, "%s: out of memory", s->path);
    }
    for (unsigned i = 0; i < sc->mNumMeshes; i++) {
        const struct aiMesh *m = sc->mMeshes[i];
        for (unsigned f = 0; m && m->mFaces && f < m->mNumFaces; f++)
            tris[i] += m->mFaces[f].mNumIndices >= 3 ? m->mFaces[f].mNumIndices - 2 : 0;
    }
    uint64_t nt = 0, nv = 0, nodes = 0;
    rs_result r = RS_OK;
    stack[top++] = (struct item){sc->mRootNode, 0};
    while (top && r == RS_OK) {
        struct item it = stack[--top];
        const struct aiNode *n = it.node;
        if (++nodes > RS_IMPORT_MAX_NODES) {
            r = rs_fail(err, RS_ERR_LIMIT, "%s: more than %u nodes; not read", s->path, RS_IMPORT_MAX_NODES);
            break;
        }
        if (it.depth > RS_IMPORT_MAX_DEPTH) {
            r = rs_fail(err, RS_ERR_LIMIT, "%s: nodes nested more than %d deep; not read", s->path, RS_IMPORT_MAX_DEPTH);
            break;
        }
        for (unsigned k = 0; n->mMeshes && k < n->mNumMeshes; k++) {
            unsigned m = n->mMeshes[k];
            if (m >= sc->mNumMeshes || !sc->mMeshes[m]) continue;  // ValidateDataStructure refuses it
            nt += tris[m];
            nv += sc->mMeshes[m]->mNumVertices;
        }
        if (nt > RS_IMPORT_MAX_TRIANGLES || nv > RS_IMPORT_MAX_VERTICES) {
            r = rs_fail(err, RS_ERR_LIMIT, "%s: its nodes instance meshes to more than %u triangles or %u vertices "
                                           "(an instancing bomb?); not read", s->path, RS_IMPORT_MAX_TRIANGLES, RS_IMPORT_MAX_VERTICES);
            break;
        }
        for (unsigned k = 0; n->mChildren && k < n->mNumChildren; k++) {
            if (!n->mChildren[k]) continue;
            if (top == cap) {
                void *p = realloc(stack, (cap *= 2) * sizeof *stack);
                if (!p) {
                    r = rs_fail(err, RS_ERR_NOMEM, "%s: out of memory", s->path);
                    break;
                }
                stack = p;
            }
            stack[top++] = (struct item){n->mChildren[k], it.depth + 1};
        }
    }
    free(tris), free(stack);
    return r;
}

// assimp's message for a file it could not read (an exception's text: std::bad_alloc is memory).
static rs_result assimp_failed(const rs_import_scene *s, rs_error *err)
{
    const char *why = aiGetErrorString();
    if (!why || !*why) why = "unknown error";
    if (strstr(why, "bad_alloc")) {
        struct rlimit rl;
        if (getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY)
            return rs_fail(err, RS_ERR_NOMEM, "%s: reading it needs more than the %llu MiB the import may use (a memory "
                                              "bomb?); not read", s->path, (unsigned long long)(rl.rlim_cur >> 20));
        return rs_fail(err, RS_ERR_NOMEM, "%s: out of memory reading it; not read", s->path);
    }
    if (s->format != RS_IMPORT_OTHER)
        return rs_fail(err, RS_ERR_FORMAT, "%s: bad %s file (assimp: %s)", s->path, rs_import_format_name(s->format), why);
    return rs_fail(err, RS_ERR_FORMAT, "%s: not a model rouge-pack can read (PLY, OBJ, glTF/GLB, FBX, STL, DAE and the "
                                       "other formats assimp reads; assimp: %s)", s->path, why);
}

// Appends a warning to the mesh's list ("; "-joined, cut to the buffer).
static void add_warning(rs_ply_mesh *m, const char *w)
{
    size_t len = strlen(m->warnings);
    snprintf(m->warnings + len, sizeof m->warnings - len, "%s%s", len ? "; " : "", w);
}

static rs_result import_assimp(rs_import_scene *s, io_ctx *ctx, const char *name, const uint8_t *head, size_t head_len,
                               rs_error *err)
{
    ctx->main = name;
    ctx->format = s->format;
    struct aiFileIO io = {.OpenProc = io_open, .CloseProc = io_close, .UserData = (aiUserData)ctx};
    struct aiPropertyStore *props = aiCreatePropertyStore();
    if (!props) return rs_fail(err, RS_ERR_NOMEM, "out of memory");
    // Only what a static surface needs: no animation, bones or lights are read where the format allows.
    aiSetImportPropertyInteger(props, AI_CONFIG_IMPORT_FBX_READ_ANIMATIONS, 0);
    aiSetImportPropertyInteger(props, AI_CONFIG_IMPORT_FBX_READ_CAMERAS, 0);
    aiSetImportPropertyInteger(props, AI_CONFIG_IMPORT_FBX_READ_LIGHTS, 0);
    aiSetImportPropertyInteger(props, AI_CONFIG_IMPORT_FBX_READ_WEIGHTS, 0);
    aiSetImportPropertyInteger(props, AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_LINE);
    // Read and validated, not yet post-processed: the node tree is checked before anything unrolls it.
    const struct aiScene *sc = aiImportFileExWithProperties(name, aiProcess_ValidateDataStructure, &io, props);
    aiReleasePropertyStore(props);
    if (!sc) {
        if (ctx->failed[0]) return rs_fail(err, RS_ERR_IO, "%s", ctx->failed);
        if (ctx->refused[0]) return rs_fail(err, RS_ERR_IO, "%s: %s", s->path, ctx->refused);
        rs_result r = assimp_failed(s, err);
        // A missing file it names (a glTF's .bin) is often why.
        if (ctx->missing[0] && err) {
            char why[sizeof err->msg];
            snprintf(why, sizeof why, "%s", err->msg);
            rs_fail(err, r, "%s; %s", why, ctx->missing);
        }
        return r;
    }
    // A file the model names that was refused is an error even where assimp went on without it.
    if (ctx->refused[0]) {
        aiReleaseImport(sc);
        return rs_fail(err, RS_ERR_IO, "%s: %s", s->path, ctx->refused);
    }
    rs_result r = check_unrolled(sc, s, err);
    if (r != RS_OK) {
        aiReleaseImport(sc);
        return r;
    }
    // No ValidateDataStructure here: it is the one step that can fail, and assimp 5.2.5's
    // aiApplyPostProcessing then frees the scene twice (SIGSEGV); the scene was validated on import.
    sc = aiApplyPostProcessing(sc, aiProcess_Triangulate | aiProcess_SortByPType | aiProcess_PreTransformVertices);
    if (!sc) return assimp_failed(s, err);
    s->priv = (void *)sc;
    s->v_flipped = s->format == RS_IMPORT_GLTF;
    if (s->format == RS_IMPORT_OTHER) {
        const char *fmt = meta_string(sc->mMetaData, "SourceAsset_Format");
        snprintf(s->format_name, sizeof s->format_name, "%s", fmt && *fmt ? fmt : "model");
    }
    r = flatten(sc, s, err);
    if (r == RS_OK) r = collect_pages(sc, s, err);
    if (r != RS_OK) return r;
    declared_unit(sc, s);
    collect_comments(sc, head, head_len, s);
    if (ctx->missing[0]) {
        char w[sizeof ctx->missing + 64];
        snprintf(w, sizeof w, "%s; converted without it", ctx->missing);
        add_warning(s->mesh, w);
    }
    return RS_OK;
}

static rs_import_scene *scene_new(const char *path)
{
    rs_import_scene *s = calloc(1, sizeof *s);
    if (s) snprintf(s->path, sizeof s->path, "%s", path);
    return s;
}

// ---- the import in a child process ----
//
// Why: the checks before assimp (import_guard.c) see the known hostile shapes in the formats people use;
// assimp reads forty more, and what it does on a crafted file is not ours to fix. So assimp reads the file
// in a forked child limited to RS_IMPORT_MAX_MEMORY of address space and RS_IMPORT_MAX_CPU_SECONDS; the
// child flattens the scene and writes the mesh and texture pages to a pipe. A stack overflow, a memory
// bomb or an endless loop then ends the child, and the parent reports it as one line naming the file.
// Lower limits a shell sets (ulimit -v) are kept. PLY stays in the process: ply.c is rouge's own.

#define WIRE_MAGIC 0x52534931u  // "RSI1"

// AddressSanitizer reserves terabytes of address space for its shadow: under it an address-space limit
// would fail every allocation, so `make asan` runs the child without one (the other limits stay).
#if defined(__SANITIZE_ADDRESS__)
#define RS_IMPORT_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define RS_IMPORT_ASAN 1
#endif
#endif
#ifndef RS_IMPORT_ASAN
#define RS_IMPORT_ASAN 0
#endif

typedef struct wire_head {
    uint32_t magic;
    rs_result result;
    char msg[sizeof ((rs_error *)0)->msg];
    rs_import_format format;
    char format_name[64];
    float declared_mm_per_unit;
    char unit_source[96];
    bool v_flipped, normal, uv, rgb, tri_page;
    uint32_t page_count, points_dropped, vertex_count, tri_count;
    uint32_t comments_len;
    char warnings[512];
} wire_head;

typedef struct wire_page {
    char name[64];
    uint32_t raw_width, raw_height;
    uint8_t wrap[2];
    uint32_t texture_len;
    uint64_t embedded_len;
} wire_page;

static bool put(int fd, const void *p, size_t n)
{
    const uint8_t *b = p;
    while (n) {
        ssize_t w = write(fd, b, n);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) return false;
        b += w, n -= (size_t)w;
    }
    return true;
}

static bool get(int fd, void *p, size_t n)
{
    uint8_t *b = p;
    while (n) {
        ssize_t r = read(fd, b, n);
        if (r < 0 && errno == EINTR) continue;
        if (r <= 0) return false;
        b += r, n -= (size_t)r;
    }
    return true;
}

static bool send_scene(int fd, rs_result result, const rs_error *e, const rs_import_scene *s)
{
    wire_head h;
    memset(&h, 0, sizeof h);  // padding too: every byte that goes down the pipe is defined
    h.magic = WIRE_MAGIC, h.result = result;
    if (result != RS_OK) {
        snprintf(h.msg, sizeof h.msg, "%s", e->msg);
        return put(fd, &h, sizeof h);
    }
    const rs_ply_mesh *m = s->mesh;
    h.format = s->format;
    memcpy(h.format_name, s->format_name, sizeof h.format_name);
    h.declared_mm_per_unit = s->declared_mm_per_unit;
    memcpy(h.unit_source, s->unit_source, sizeof h.unit_source);
    h.v_flipped = s->v_flipped, h.normal = m->normal, h.uv = m->uv, h.rgb = m->rgb, h.tri_page = m->tri_page;
    h.page_count = s->page_count, h.points_dropped = s->points_dropped;
    h.vertex_count = m->vertex_count, h.tri_count = m->tri_count;
    h.comments_len = (uint32_t)strlen(m->comments);
    memcpy(h.warnings, m->warnings, sizeof h.warnings);
    size_t nv = m->vertex_count, nt = m->tri_count;
    bool ok = put(fd, &h, sizeof h) && put(fd, m->pos, nv * sizeof *m->pos) &&
              (!m->normal || put(fd, m->normal, nv * sizeof *m->normal)) && (!m->uv || put(fd, m->uv, nv * sizeof *m->uv)) &&
              (!m->rgb || put(fd, m->rgb, nv * sizeof *m->rgb)) && (!m->tri || put(fd, m->tri, nt * sizeof *m->tri)) &&
              (!m->tri_page || put(fd, m->tri_page, nt * sizeof *m->tri_page)) && put(fd, m->comments, h.comments_len);
    for (uint32_t i = 0; ok && i < s->page_count; i++) {
        const rs_import_page *p = &s->pages[i];
        wire_page w;
        memset(&w, 0, sizeof w);  // padding too
        w.texture_len = p->texture ? (uint32_t)strlen(p->texture) : 0, w.embedded_len = p->embedded_len;
        w.raw_width = p->raw_width, w.raw_height = p->raw_height;
        memcpy(w.wrap, p->wrap, sizeof w.wrap);
        memcpy(w.name, p->name, sizeof w.name);
        ok = put(fd, &w, sizeof w) && put(fd, p->texture, w.texture_len) && (!p->embedded || put(fd, p->embedded, p->embedded_len));
    }
    return ok;
}

static void *get_array(int fd, bool want, size_t count, size_t size, bool *ok)
{
    if (!want || !*ok) return NULL;
    void *p = rs_alloc_array(count ? count : 1, size);
    *ok = p && get(fd, p, count * size);
    return p;
}

// The child's scene into s; false when the pipe ended early (the child died: the caller says why).
static bool receive_scene(int fd, rs_import_scene *s, rs_result *result, rs_error *err)
{
    wire_head h;
    if (!get(fd, &h, sizeof h) || h.magic != WIRE_MAGIC) return false;
    h.msg[sizeof h.msg - 1] = h.format_name[63] = h.unit_source[95] = h.warnings[511] = 0;
    if (h.result != RS_OK) {
        // Already made terminal-safe in the child.
        if (err) err->code = h.result, snprintf(err->msg, sizeof err->msg, "%s", h.msg);
        *result = h.result;
        return true;
    }
    if (h.vertex_count > RS_IMPORT_MAX_VERTICES || h.tri_count > RS_IMPORT_MAX_TRIANGLES ||
        h.page_count > RS_IMPORT_MAX_PAGES || h.comments_len > (1u << 20) || h.format > RS_IMPORT_OTHER)
        return false;
    s->format = h.format;
    memcpy(s->format_name, h.format_name, sizeof s->format_name);
    s->declared_mm_per_unit = h.declared_mm_per_unit;
    memcpy(s->unit_source, h.unit_source, sizeof s->unit_source);
    s->v_flipped = h.v_flipped, s->points_dropped = h.points_dropped;
    rs_ply_mesh *m = calloc(1, sizeof *m);
    if (!m) return false;
    s->mesh = m;
    size_t nv = h.vertex_count, nt = h.tri_count;
    bool ok = true;
    m->vertex_count = h.vertex_count, m->tri_count = h.tri_count;
    m->pos = get_array(fd, true, nv, sizeof *m->pos, &ok);
    m->normal = get_array(fd, h.normal, nv, sizeof *m->normal, &ok);
    m->uv = get_array(fd, h.uv, nv, sizeof *m->uv, &ok);
    m->rgb = get_array(fd, h.rgb, nv, sizeof *m->rgb, &ok);
    m->tri = get_array(fd, nt > 0, nt, sizeof *m->tri, &ok);
    m->tri_page = get_array(fd, h.tri_page, nt, sizeof *m->tri_page, &ok);
    m->comments = ok ? calloc(h.comments_len + 1, 1) : NULL;
    if (!m->comments || !get(fd, m->comments, h.comments_len)) return false;
    memcpy(m->warnings, h.warnings, sizeof m->warnings);
    // Indices are checked again: the child is ours, but a mesh with a bad index must not reach the sampler.
    for (size_t t = 0; t < nt; t++)
        for (int c = 0; c < 3; c++)
            if (m->tri[t][c] >= nv) return false;
    if (h.page_count) {
        s->pages = calloc(h.page_count, sizeof *s->pages);
        if (!s->pages) return false;
        s->page_count = h.page_count;
    }
    for (uint32_t i = 0; i < h.page_count; i++) {
        rs_import_page *p = &s->pages[i];
        wire_page w;
        if (!get(fd, &w, sizeof w) || w.texture_len > 4096 || w.embedded_len > RS_IMPORT_MAX_FILE) return false;
        memcpy(p->name, w.name, sizeof p->name);
        p->name[sizeof p->name - 1] = 0;
        if (w.raw_width > RS_IMAGE_MAX_DIM || w.raw_height > RS_IMAGE_MAX_DIM || w.wrap[0] > RS_PACK_WRAP_MIRROR ||
            w.wrap[1] > RS_PACK_WRAP_MIRROR || (w.raw_height && w.embedded_len != (uint64_t)w.raw_width * w.raw_height * 4))
            return false;
        p->raw_width = w.raw_width, p->raw_height = w.raw_height;
        memcpy(p->wrap, w.wrap, sizeof p->wrap);
        if (w.texture_len) {
            p->texture = calloc(w.texture_len + 1, 1);
            if (!p->texture || !get(fd, p->texture, w.texture_len)) return false;
        }
        if (w.embedded_len) {
            p->embedded_copy = malloc(w.embedded_len);
            if (!p->embedded_copy || !get(fd, p->embedded_copy, w.embedded_len)) return false;
            p->embedded = p->embedded_copy;
            p->embedded_len = w.embedded_len;
        }
    }
    *result = RS_OK;
    return true;
}

static void set_limit(int resource, rlim_t soft, rlim_t hard)
{
    struct rlimit rl;
    if (getrlimit(resource, &rl) != 0) return;
    // Only ever lowered: a limit the shell set stays.
    if (rl.rlim_max != RLIM_INFINITY && hard > rl.rlim_max) hard = rl.rlim_max;
    if (rl.rlim_cur != RLIM_INFINITY && soft > rl.rlim_cur) soft = rl.rlim_cur;
    rl.rlim_cur = RS_MIN(soft, hard), rl.rlim_max = hard;
    setrlimit(resource, &rl);
}

static rs_result import_file(const char *path, const rs_import_desc *desc, const uint8_t *head, size_t head_len,
                             rs_import_scene *s, rs_error *err)
{
    io_ctx ctx = {.disk = true, .allow_outside = desc->allow_outside_paths};
    model_folder(path, ctx.dir, sizeof ctx.dir);
    return import_assimp(s, &ctx, path, head, head_len, err);
}

static rs_result import_in_child(const char *path, const rs_import_desc *desc, const uint8_t *head, size_t head_len,
                                 rs_import_scene *s, rs_error *err)
{
    int fds[2];
    if (pipe(fds) != 0) return rs_fail(err, RS_ERR_IO, "%s: cannot start the import: %s", path, strerror(errno));
    pid_t pid = fork();
    if (pid < 0) {
        close(fds[0]), close(fds[1]);
        return rs_fail(err, RS_ERR_IO, "%s: cannot start the import: %s", path, strerror(errno));
    }
    if (pid == 0) {
        close(fds[0]);
        if (!RS_IMPORT_ASAN) set_limit(RLIMIT_AS, RS_IMPORT_MAX_MEMORY, RS_IMPORT_MAX_MEMORY);
        set_limit(RLIMIT_CPU, RS_IMPORT_MAX_CPU_SECONDS, RS_IMPORT_MAX_CPU_SECONDS + 5);
        set_limit(RLIMIT_CORE, 0, 0);
        rs_error e = {0};
        rs_result r = import_file(path, desc, head, head_len, s, &e);
        // _exit: the parent's stdio buffers and atexit handlers are the parent's.
        _exit(send_scene(fds[1], r, &e, s) ? 0 : 3);
    }
    close(fds[1]);
    rs_result result = RS_ERR_IO;
    bool got = receive_scene(fds[0], s, &result, err);
    close(fds[0]);
    // A child still writing what the parent refused to read is stopped, not waited for.
    if (!got) kill(pid, SIGKILL);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {}
    if (got) return result;
    if (WIFSIGNALED(status)) {
        int sig = WTERMSIG(status);
        if (sig == SIGSEGV || sig == SIGBUS)
            return rs_fail(err, RS_ERR_FORMAT, "%s: assimp crashed reading it (signal %d, %s: a fault in assimp's "
                                               "reader, e.g. a stack overflow on nodes nested too deeply); not read",
                           path, sig, sig == SIGSEGV ? "SIGSEGV" : "SIGBUS");
        if (sig == SIGXCPU)
            return rs_fail(err, RS_ERR_LIMIT, "%s: reading it took more than %d s of CPU time (a work bomb?); not read", path,
                           RS_IMPORT_MAX_CPU_SECONDS);
        if (sig == SIGABRT)
            return rs_fail(err, RS_ERR_NOMEM, "%s: assimp aborted reading it (out of memory or a failed check); not read", path);
        return rs_fail(err, RS_ERR_IO, "%s: the import was stopped by signal %d (%s); not read", path, sig, strsignal(sig));
    }
    return rs_fail(err, RS_ERR_IO, "%s: the import process failed (exit %d); not read", path,
                   WIFEXITED(status) ? WEXITSTATUS(status) : -1);
}

rs_result rs_import_load(const char *path, rs_import_scene **out, rs_error *err)
{
    return rs_import_load_with(path, NULL, out, err);
}

rs_result rs_import_load_with(const char *path, const rs_import_desc *desc, rs_import_scene **out, rs_error *err)
{
    static const rs_import_desc defaults;
    if (!desc) desc = &defaults;
    // The head of the file, read non-blocking from a regular file only (a FIFO would block the read).
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return rs_fail(err, RS_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        close(fd);
        return rs_fail(err, RS_ERR_IO, "%s: not a regular file", path);
    }
    uint8_t head[4096];
    ssize_t got = read(fd, head, sizeof head);
    close(fd);
    if (got < 0) return rs_fail(err, RS_ERR_IO, "%s: cannot read: %s", path, strerror(errno));
    const char *ext = ext_of(path);
    rs_import_scene *s = scene_new(path);
    if (!s) return rs_fail(err, RS_ERR_NOMEM, "out of memory");
    s->allow_outside_paths = desc->allow_outside_paths;
    rs_result r;
    if (is_ply_magic(head, (size_t)got) || !strcasecmp(ext, "ply")) {
        s->format = RS_IMPORT_PLY;
        r = rs_ply_load(path, &s->mesh, err);
    } else if (got == 0) {
        r = rs_fail(err, RS_ERR_FORMAT, "%s: file is empty", path);
    } else {
        s->format = sniff(head, (size_t)got, ext);
        r = desc->in_process ? import_file(path, desc, head, (size_t)got, s, err)
                             : import_in_child(path, desc, head, (size_t)got, s, err);
    }
    if (!s->format_name[0]) snprintf(s->format_name, sizeof s->format_name, "%s", rs_import_format_name(s->format));
    if (r != RS_OK) {
        rs_import_destroy(s);
        return r;
    }
    *out = s;
    return RS_OK;
}

rs_result rs_import_load_memory(const void *data, size_t len, const char *hint, rs_import_scene **out, rs_error *err)
{
    char name[32];
    snprintf(name, sizeof name, "model.%s", hint && *hint ? hint : "bin");
    rs_import_scene *s = scene_new(name);
    if (!s) return rs_fail(err, RS_ERR_NOMEM, "out of memory");
    rs_result r;
    if (is_ply_magic(data, len)) {
        s->format = RS_IMPORT_PLY;
        r = rs_ply_load_memory(data, len, &s->mesh, err);
    } else if (len == 0) {
        r = rs_fail(err, RS_ERR_FORMAT, "%s: file is empty", name);
    } else {
        s->format = sniff(data, RS_MIN(len, (size_t)4096), ext_of(name));
        io_ctx ctx = {.mem_name = name, .mem = data, .mem_len = len};
        r = import_assimp(s, &ctx, name, data, RS_MIN(len, (size_t)4096), err);
    }
    if (!s->format_name[0]) snprintf(s->format_name, sizeof s->format_name, "%s", rs_import_format_name(s->format));
    if (r != RS_OK) {
        rs_import_destroy(s);
        return r;
    }
    *out = s;
    return RS_OK;
}

void rs_import_destroy(rs_import_scene *s)
{
    if (!s) return;
    rs_ply_destroy(s->mesh);
    for (uint32_t i = 0; i < s->page_count && s->pages; i++) {
        free(s->pages[i].texture);
        free(s->pages[i].embedded_copy);
    }
    free(s->pages);
    if (s->priv) aiReleaseImport(s->priv);
    free(s);
}

// ---- textures ----

// A texture path from a material: relative to the model's folder. Windows paths are accepted: '\' is a
// separator, and a drive letter or a leading separator ("C:\x\skin.png", "\textures\skin.png": where the
// file lay on the machine that made it) is dropped, so the path is looked for below the model's folder,
// then the bare file name there. A path outside the model's folder is not read unless the scene allows it
// (rs_import_desc); errors never quote the file's bytes. Why it failed goes to err (a warning's text).
static rs_result load_page_file(const rs_import_scene *s, const rs_import_page *p, rs_image *out, rs_error *err)
{
    char rel[1024];
    snprintf(rel, sizeof rel, "%s", p->texture);
    for (char *c = rel; *c; c++)
        if (*c == '\\') *c = '/';
    const char *stripped = rel;
    if (((rel[0] | 0x20) >= 'a' && (rel[0] | 0x20) <= 'z') && rel[1] == ':') stripped += 2;
    while (*stripped == '/') stripped++;
    char dir[4096];
    snprintf(dir, sizeof dir, "%s", s->path);
    char *slash = strrchr(dir, '/');
    if (slash) slash[1] = 0;
    else dir[0] = 0;
    char folder[4096];
    model_folder(s->path, folder, sizeof folder);
    char full[8192];
    const char *tries[3] = {rel, stripped, base_name(rel)};
    bool outside = false;
    for (int k = 0; k < 3; k++) {
        if (!tries[k][0] || (k > 0 && !strcmp(tries[k], tries[k - 1]))) continue;
        if (tries[k][0] == '/') snprintf(full, sizeof full, "%s", tries[k]);
        else snprintf(full, sizeof full, "%s%s", dir, tries[k]);
        struct stat st;
        if (stat(full, &st) != 0) continue;
        if (!s->allow_outside_paths && (!folder[0] || !inside_folder(folder, full))) {
            outside = true;
            continue;
        }
        rs_result r = rs_image_load_referenced(full, out, err);
        if (r != RS_OK) {
            char why[sizeof err->msg];
            snprintf(why, sizeof why, "%s", err->msg);
            return rs_fail(err, r, "texture %s", why);
        }
        return RS_OK;
    }
    if (outside)
        return rs_fail(err, RS_ERR_IO, "names the texture '%s', outside the model's folder: not read "
                                       "(--allow-outside-paths reads it, --texture FILE uses another image)", p->texture);
    return rs_fail(err, RS_ERR_IO, "names the texture '%s', which is not there (looked in '%s'; --texture FILE uses "
                                   "another image)", p->texture, dir[0] ? dir : "./");
}

// assimp's aiTexel rows (B G R A) as an RGB image.
static rs_result decode_texels(const rs_import_page *p, rs_image *out, rs_error *err)
{
    size_t n = (size_t)p->raw_width * p->raw_height;
    uint8_t *px = rs_alloc_array(n ? n : 1, 3);
    if (!px) return rs_fail(err, RS_ERR_NOMEM, "out of memory for a %ux%u texture", p->raw_width, p->raw_height);
    for (size_t i = 0; i < n; i++)
        px[3 * i] = p->embedded[4 * i + 2], px[3 * i + 1] = p->embedded[4 * i + 1], px[3 * i + 2] = p->embedded[4 * i];
    *out = (rs_image){.width = (int)p->raw_width, .height = (int)p->raw_height, .channels = 3, .pixels = px};
    return RS_OK;
}

static void append(char *buf, size_t cap, const char *w)
{
    if (!buf || !cap) return;
    size_t len = strnlen(buf, cap - 1);
    snprintf(buf + len, cap - len, "%s%s", len ? "; " : "", w);
}

rs_result rs_import_load_pages(const rs_import_scene *s, rs_image **out, char *warnings, size_t cap, rs_error *err)
{
    *out = NULL;
    if (!s->page_count) return RS_OK;
    rs_image *pages = calloc(s->page_count, sizeof *pages);
    if (!pages) return rs_fail(err, RS_ERR_NOMEM, "out of memory");
    const char *instead = s->mesh && s->mesh->rgb ? "its vertex colours" : "the default grey";
    for (uint32_t i = 0; i < s->page_count; i++) {
        const rs_import_page *p = &s->pages[i];
        rs_error e = {0};
        rs_result r = RS_OK;
        if (p->embedded && p->raw_height) {
            r = decode_texels(p, &pages[i], &e);
        } else if (p->embedded) {
            r = rs_image_decode_any(p->embedded, p->embedded_len, "embedded texture", &pages[i], &e);
        } else if (p->texture && !strcmp(base_name(p->texture), "$texture_dummy.bmp")) {
            // assimp's stand-in when a format names a skin it could not find (MD2, MD3): nothing to read.
            r = rs_fail(&e, RS_ERR_FORMAT, "has assimp's placeholder texture '$texture_dummy.bmp' (the file names no "
                                           "texture assimp found)");
        } else if (p->texture) {
            r = load_page_file(s, p, &pages[i], &e);
        }
        if (r == RS_ERR_NOMEM) {
            rs_import_free_pages(pages, s->page_count);
            return rs_fail(err, r, "%s: material '%s': %s", s->path, p->name, e.msg);
        }
        if (r != RS_OK) {
            rs_image_free(&pages[i]);
            char w[sizeof e.msg + 192];
            snprintf(w, sizeof w, "material '%s' %s; coloured from %s instead", p->name, e.msg, instead);
            append(warnings, cap, w);
        }
    }
    *out = pages;
    return RS_OK;
}

void rs_import_free_pages(rs_image *pages, uint32_t count)
{
    for (uint32_t i = 0; pages && i < count; i++) rs_image_free(&pages[i]);
    free(pages);
}
