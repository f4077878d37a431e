// rouge_pack.c — rouge-pack: converts a scan (PLY, OBJ, glTF, FBX, ...: point cloud or textured mesh) into an .rsf splat file,
// and prints what an .rsf holds (see tools/pack/pack.h for the steps, docs/rsf.md for the format).
//
// Exit status: 0 done, 1 the conversion or a file failed, 2 usage. Errors are one "rouge-pack: ..." line
// on stderr; a progress bar goes to stderr only when it is a terminal; the summary goes to stdout.
#define _POSIX_C_SOURCE 200809L
#include "pack/import.h"
#include "pack/pack.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

static const char usage[] =
    "usage: rouge-pack INPUT -o OUT.rsf [options]\n"
    "       rouge-pack --info FILE.rsf [--preview PNG]\n"
    "       rouge-pack OLD.rsf -o NEW.rsf    (rewrites an .rsf as version 2, records and notes as they are)\n"
    "       rouge-pack --ao FILE.rsf -o OUT.rsf\n"
    "\n"
    "Converts a scan into rouge's compact splat file (.rsf version 2: about 8 bytes per splat, entropy-\n"
    "coded, the coarsest LOD level first so viewers can show it while the rest loads): normals (estimated\n"
    "by k-nearest-neighbour PCA when the input has none), a radius per splat from the local spacing, LOD\n"
    "order (every prefix in the LOD table is an even subsample), and face regions for the skin BRDF.\n"
    "\n"
    "Input: PLY (ASCII or binary, rouge's own reader), or through assimp OBJ (+ MTL), glTF / GLB, FBX,\n"
    "STL, DAE, 3DS, OFF and the other formats assimp reads. A point cloud is used as it is, a mesh is\n"
    "sampled area-uniformly. Colour: --texture, else each material's base-colour texture (MTL map_Kd,\n"
    "glTF baseColorTexture, embedded GLB images; PNG, JPEG, BMP or TGA; several materials sample each face from\n"
    "its own page), else the vertex colours.\n"
    "  --points N          mesh: number of splats to sample (default 600000); cloud: decimate to N\n"
    "                      (a Poisson-disk-like subset); default keeps every point\n"
    "  --texture IMAGE     sRGB colour map (PNG, JPEG, BMP, TGA) for every face, sampled bilinearly at (s, 1 - t)\n"
    "                      with the coordinates as the file stores them: t = 0 is the bottom row\n"
    "  --normal-map PNG    tangent-space normal map (OpenGL convention, +G along +t); mesh only\n"
    "  --specular-map PNG  specular-intensity map: measured per region and printed in the summary only;\n"
    "                      the .rsf keeps per-region m and rho_s (Weyrich et al. means), not per splat\n"
    "  --region-map PNG    region ids in UV space: black other, red cheek, green nose, blue forehead,\n"
    "                      yellow lips, white = automatic. A per-vertex `region` PLY property (0 other,\n"
    "                      1 cheek, 2 nose, 3 forehead, 4 lips) is used the same way\n"
    "  --all-components    mesh: sample every connected component; by default only the largest (by\n"
    "                      area) is kept, which on a scan is the skin, not caps or mouth/eye pockets\n"
    "  Inputs without colour get a light warm grey (sRGB 200 178 160).\n"
    "  --allow-outside-paths  read files the model names (MTL, glTF buffers, textures) from anywhere; by\n"
    "                      default only from the model's folder and below (a model cannot make rouge-pack\n"
    "                      read /etc/passwd or ../../secret; a texture named outside it is looked for by\n"
    "                      its bare name in the folder). A missing MTL is a warning; a named file that is\n"
    "                      not a regular file (a FIFO, /dev/zero, a directory) is an error\n"
    "  Hostile models: nesting deeper than 256 levels, nodes that contain themselves, arrays claiming more\n"
    "  than their compressed bytes hold and instancing past the triangle limit are refused before they\n"
    "  are expanded; assimp reads the file in a child process limited to 8 GiB and 600 CPU seconds.\n"
    "\n"
    "Face (one front-facing head: a bust, a whole head or a face-only scan; the nose is its sharpest\n"
    "bump). Its frame is found from the scan in any orientation: the mirror plane, the nose, the\n"
    "face's mean normal, and a depth template of the face for up versus down. To fix it, give axes:\n"
    "  --up AXIS           +x -x +y -y +z -z (with --up or --forward given: default +y)\n"
    "  --forward AXIS      the direction the face looks (default then +z)\n"
    "  --units U           the scan's unit: mm, cm, m or in\n"
    "  --mm-per-unit X     the same as a number (the bundled head is about 47 mm per unit)\n"
    "  Scale (it sets the skin's scattering width) when neither is given: the unit the file declares\n"
    "  (glTF: metres; FBX: UnitScaleFactor; DAE: <unit>) unless it makes the head (vertex to chin)\n"
    "  shorter than 60 mm or taller than 600 mm; else the first of mm, cm, m, in that makes the head\n"
    "  150..300 mm tall (only one can); else the head is taken as 225 mm. The summary says which rule\n"
    "  applied; an inferred or estimated scale is also noted on stderr, even with -q\n"
    "\n"
    "Output:\n"
    "  -o, --output FILE   the .rsf to write (atomically: no file is left on failure)\n"
    "  --min-lod N         smallest LOD prefix listed (default 10000)\n"
    "  --no-ao             skip the per-splat ambient occlusion and bent normals (environment lighting\n"
    "                      then treats every splat as open to the sky: eye sockets and nostrils lit\n"
    "                      like the cheek)\n"
    "  --seed S            random seed for sampling (default 20240600); same seed, same file\n"
    "  --preview PNG       also write a CPU preview: front colour, front regions, side regions\n"
    "  -q, --quiet         no progress bar, no summary\n"
    "  --info FILE.rsf     print counts, bytes per splat, LOD and region tables, frame and notes\n"
    "  --ao FILE.rsf       (re)compute an .rsf's ambient occlusion and bent normals (the direction each\n"
    "                      splat sees the sky in; normals move onto a 10-bit lattice under them), all\n"
    "                      else kept (its version too); files from before rouge-pack computed them\n"
    "                      light every splat as if open to the sky, or around its normal. OUT may be FILE\n"
    "  -h, --help          this text\n"
    "\n"
    "Exit status: 0 done, 1 conversion or file error, 2 usage.\n";

static int fail(int code, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static int fail(int code, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fputs("rouge-pack: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
    return code;
}

// Parses all of s as an integer in [lo, hi].
static bool parse_u64(const char *s, uint64_t lo, uint64_t hi, uint64_t *out)
{
    char *end;
    errno = 0;
    if (!s[0] || s[0] == '-') return false;
    unsigned long long v = strtoull(s, &end, 10);
    if (*end || errno || v < lo || v > hi) return false;
    *out = v;
    return true;
}

// A scale factor: a number > 0 (and at most 1e30).
static bool parse_scale(const char *s, float *out)
{
    double v;
    if (!rs_parse_number(s, 0.0, 1e30, &v) || !(v > 0)) return false;
    *out = (float)v;
    return true;
}

static long long file_size(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 ? (long long)st.st_size : -1;
}

// ---- progress bar (stderr, terminals only) ----

typedef struct progress {
    bool on;
    int last_step, last_pct;
} progress;

static void show_progress(void *user, rs_pack_step step, double f)
{
    progress *p = user;
    int pct = (int)(RS_CLAMP(f, 0.0, 1.0) * 100.0);
    if ((int)step == p->last_step && pct == p->last_pct) return;
    p->last_step = (int)step;
    p->last_pct = pct;
    char bar[31];
    int full = pct * 30 / 100;
    for (int i = 0; i < 30; i++) bar[i] = i < full ? '#' : '.';
    bar[30] = 0;
    fprintf(stderr, "\r  %-10s [%s] %3d%%", rs_pack_step_name(step), bar, pct);
    if ((step == RS_PACK_STEP_ENCODE || step == RS_PACK_STEP_AO) && pct == 100) fputs("\r\033[K", stderr);
    fflush(stderr);
}

// ---- --info ----

// How many bytes of the file a progressive reader needs before the coarsest LOD level can be drawn:
// the file fed to rs_splat_loader byte by byte (0 for a version-1 file, which decodes only whole).
static uint64_t first_level_bytes(const char *path)
{
    FILE *f = fopen(path, "rb");
    rs_splat_loader *l = NULL;
    if (!f || rs_splat_loader_create(&(rs_splat_loader_desc){.name = path}, &l, NULL) != RS_OK) {
        if (f) fclose(f);
        return 0;
    }
    uint64_t at = 0, found = 0;
    int ch;
    while (!found && (ch = fgetc(f)) != EOF) {
        unsigned char b = (unsigned char)ch;
        if (rs_splat_loader_feed(l, &b, 1, NULL) != RS_OK) break;
        at++;
        if (rs_splat_loader_ready(l)) found = at;
    }
    fclose(f);
    rs_splat_loader_destroy(l);
    return found;
}

// The version field of a file that has just loaded (bytes 4..7, little-endian).
static unsigned file_version(const char *path)
{
    uint8_t b[8] = {0};
    FILE *f = fopen(path, "rb");
    if (f) {
        if (fread(b, 1, sizeof b, f) != sizeof b) memset(b, 0, sizeof b);
        fclose(f);
    }
    return rs_le32_get(b + 4);
}

static int info(const char *path, const char *preview)
{
    rs_error err = {0};
    rs_splat_cloud *c = NULL;
    if (rs_splat_load(path, &c, &err) != RS_OK) return fail(1, "%s", err.msg);
    const rs_splat_header *h = &c->hdr;
    long long size = file_size(path);
    printf("%s\n", path);
    printf("  splats        %u\n", h->count);
    printf("  file size     %lld bytes (%.2f bytes/splat, .rsf version %u)\n", size,
           h->count ? (double)size / h->count : 0.0, file_version(path));
    uint64_t first = first_level_bytes(path);
    if (first)
        printf("  first level   %u splats, drawable after %llu bytes (%.1f%% of the file)\n", h->lods[h->lod_count - 1],
               (unsigned long long)first, 100.0 * (double)first / (double)size);
    printf("  bbox          (%.4f %.4f %.4f) .. (%.4f %.4f %.4f) units\n", h->bbox_min[0], h->bbox_min[1],
           h->bbox_min[2], h->bbox_max[0], h->bbox_max[1], h->bbox_max[2]);
    printf("  radius        %.5f .. %.5f units (%.3f .. %.3f mm)\n", h->radius_min, h->radius_max,
           h->radius_min * h->mm_per_unit, h->radius_max * h->mm_per_unit);
    printf("  mm_per_unit   %.3f\n", h->mm_per_unit);
    printf("  face height   %.4f units (%.1f mm)\n", h->face_height, h->face_height * h->mm_per_unit);
    printf("  centre        (%.4f %.4f %.4f)\n", h->centre[0], h->centre[1], h->centre[2]);
    printf("  forward       (%.4f %.4f %.4f)\n", h->forward[0], h->forward[1], h->forward[2]);
    printf("  up            (%.4f %.4f %.4f)\n", h->up[0], h->up[1], h->up[2]);
    printf("  LOD prefixes  %u\n", h->lod_count);
    for (uint32_t i = 0; i < h->lod_count; i++)
        printf("    %2u  %9u splats  %6.2f%%  radius x %.3f\n", i, h->lods[i], 100.0 * h->lods[i] / h->count,
               rs_splat_lod_radius_scale(c, h->lods[i]));
    if (h->flags & RS_SPLAT_FLAG_AO) {
        double sum = 0;
        uint32_t low = 0;
        for (uint32_t i = 0; i < h->count; i++) {
            float a = rs_splat_ao(c, i);
            sum += a;
            low += a < 0.5f;
        }
        printf("  occlusion     ambient occlusion per splat: mean %.3f, %.1f%% below 0.5\n", sum / h->count,
               100.0 * low / h->count);
        if (h->flags & RS_SPLAT_FLAG_BENT) {
            // How far the open sky's axis turns from the normal: the mean angle.
            double turn = 0;
            for (uint32_t i = 0; i < h->count; i++) {
                float b[3], *n = c->normal[i];
                rs_splat_bent(c, i, b);
                turn += acos(RS_CLAMP(b[0] * n[0] + b[1] * n[1] + b[2] * n[2], -1.0f, 1.0f));
            }
            printf("  bent normals  mean %.1f degrees from the normal\n", turn / h->count * 57.29578);
        } else {
            printf("  bent normals  none (environments light a hemisphere around the normal; rouge-pack --ao adds them)\n");
        }
    } else {
        printf("  occlusion     none (every splat open to the sky; rouge-pack --ao adds it)\n");
    }
    printf("  regions       %u\n", h->region_count);
    for (uint32_t i = 0; i < h->region_count; i++)
        printf("    %2u  %-10s m %.4f  rho_s %.4f  %9u splats (%5.2f%%)\n", i, h->regions[i].name, h->regions[i].m,
               h->regions[i].rho_s, c->region_counts[i], 100.0 * c->region_counts[i] / h->count);
    printf("  notes\n");
    // Notes come from the file: printed terminal-safe (no escape sequences, no bidi overrides).
    size_t cap = 8 * strlen(h->notes) + 1;
    char *line = malloc(cap);
    const char *s = h->notes;
    while (line && *s) {
        const char *e = strchr(s, '\n');
        size_t len = e ? (size_t)(e - s) : strlen(s);
        rs_text_sanitize(line, cap, s, len);
        printf("    %s\n", line);
        s += len + (e ? 1 : 0);
    }
    free(line);
    int rc = 0;
    if (preview) {
        rs_image img = {0};
        if (rs_pack_preview(c, 512, &img, &err) != RS_OK || rs_image_write_png(preview, &img, &err) != RS_OK)
            rc = fail(1, "%s", err.msg);
        rs_image_free(&img);
    }
    rs_splat_destroy(c);
    return rc;
}

// ---- an .rsf rewritten in the newest version ----

// A regular file that starts with the .rsf magic (O_NONBLOCK: a FIFO must not block here; the
// converter's reader refuses anything that is not a regular file).
static bool is_rsf(const char *path)
{
    unsigned char b[4] = {0};
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return false;
    struct stat st;
    bool yes = fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && read(fd, b, 4) == 4 && memcmp(b, "RSF\0", 4) == 0;
    close(fd);
    return yes;
}

// The records, LOD order, regions and notes as they are: how a version-1 file becomes a version-2 one.
static int rewrite(const char *in, const char *out, bool quiet)
{
    rs_error err = {0};
    rs_splat_cloud *c = NULL;
    if (rs_splat_load(in, &c, &err) != RS_OK) return fail(1, "%s", err.msg);
    rs_result r = rs_splat_save(c, out, &err);
    uint32_t n = c->hdr.count;
    rs_splat_destroy(c);
    if (r != RS_OK) return fail(1, "%s", err.msg);
    if (!quiet)
        printf("rouge-pack: %s -> %s: %u splats rewritten as .rsf version 2, %.2f bytes/splat (was %.2f)\n", in, out, n,
               (double)file_size(out) / n, (double)file_size(in) / n);
    return 0;
}

// --ao: the occlusion of an existing file recomputed, the rest of it kept, its version too (rewriting
// it as the newest version is the plain `rouge-pack OLD.rsf -o NEW.rsf`).
static int recompute_ao(const char *path, const char *output, bool quiet)
{
    rs_error err = {0};
    rs_splat_cloud *c = NULL;
    if (rs_splat_load(path, &c, &err) != RS_OK) return fail(1, "%s", err.msg);
    // The version field (bytes 4..7, little-endian) of a file that just loaded.
    uint8_t b[8] = {0};
    FILE *f = fopen(path, "rb");
    size_t got = f ? fread(b, 1, sizeof b, f) : 0;
    if (f) fclose(f);
    uint32_t version = got == sizeof b ? (uint32_t)b[4] | (uint32_t)b[5] << 8 | (uint32_t)b[6] << 16 | (uint32_t)b[7] << 24 : 0;
    double t0 = rs_time_now();
    int rc = 0;
    if (rs_pack_ao_cloud(c, &err) != RS_OK ||
        rs_splat_save_with(c, output, &(rs_splat_save_desc){.version = version == 1 ? 1 : 0}, &err) != RS_OK)
        rc = fail(1, "%s", err.msg);
    else if (!quiet)
        printf("rouge-pack: %s -> %s: ambient occlusion of %u splats (%.2f s)\n", path, output, c->hdr.count,
               rs_time_now() - t0);
    rs_splat_destroy(c);
    return rc;
}

// ---- conversion ----

typedef struct options {
    const char *input, *output, *preview;
    char texture_hint[256];  // the mesh's "TextureFile" comment when --texture was not given
    const char *maps[4];  // texture, normal, specular, region
    rs_pack_desc desc;
    bool quiet;
    rs_import_desc import;
    char format[64];          // what the input was read as ("PLY", "glTF 2.0", ...)
    char declared_unit[96];   // the unit the file declares, in words (or "")
    const char *units;        // --units as given
    uint32_t pages_textured;  // materials whose own texture coloured the splats
} options;

static const char *const map_flag[4] = {"--texture", "--normal-map", "--specular-map", "--region-map"};

static void print_summary(const options *o, const rs_splat_cloud *c, const rs_pack_report *rep, double load_s,
                          double save_s)
{
    const rs_pack_face *f = &rep->face;
    long long in_size = file_size(o->input), out_size = file_size(o->output);
    printf("rouge-pack: %s -> %s\n", o->input, o->output);
    if (rep->sampled_mesh)
        printf("  input         %s mesh, %u vertices, %u triangles (%u outside the largest component, skipped)\n",
               o->format, rep->input_vertices, rep->input_triangles, rep->triangles_dropped);
    else
        printf("  input         %s point cloud, %u points%s\n", o->format, rep->input_vertices,
               rep->duplicates_dropped ? " (duplicates dropped)" : "");
    if (rep->duplicates_dropped) printf("  duplicates    %u points at the same position dropped\n", rep->duplicates_dropped);
    printf("  splats        %u%s\n", rep->splats, rep->sampled_mesh ? " (area-uniform samples)" : "");
    if (rep->normals_replaced)
        printf("  normals       from the input; %u zero or not finite, re-estimated (16-NN PCA)\n",
               rep->normals_replaced);
    else
        printf("  normals       %s\n", rep->normals_estimated ? "estimated (16-NN PCA, MST orientation)" : "from the input");
    if (o->pages_textured)
        printf("  colour        from the %s (%u page%s)\n", o->pages_textured > 1 ? "materials' textures" : "material's texture",
               o->pages_textured, o->pages_textured > 1 ? "s" : "");
    else
        printf("  colour        %s\n", rep->colour_default ? "none in the input: light warm grey (sRGB 200 178 160)"
                                                            : o->maps[0]           ? "from the texture"
                                                            : rep->sampled_mesh    ? "from the input's vertex colours"
                                                                                   : "from the input");
    if (!rep->colour_default && rep->colour_default_points)
        printf("                %.1f%% of the splats light warm grey (no readable texture or vertex colour there)\n",
               100.0 * rep->colour_default_points / (rep->splats ? rep->splats : 1));
    if (o->texture_hint[0])
        printf("  note          the PLY names the texture '%s'; pass --texture to colour from it\n", o->texture_hint);
    printf("  size          %lld bytes = %.2f bytes/splat (input %s: %lld bytes = %.2f bytes/%s)\n", out_size,
           (double)out_size / c->hdr.count, o->format, in_size, (double)in_size / (rep->input_vertices ? rep->input_vertices : 1),
           rep->sampled_mesh ? "vertex" : "point");
    printf("  LOD           %u prefix%s:", c->hdr.lod_count, c->hdr.lod_count == 1 ? "" : "es");
    for (uint32_t i = 0; i < c->hdr.lod_count; i++) printf(" %u", c->hdr.lods[i]);
    printf("\n");
    if (f->found) {
        printf("  face          nose tip (%.3f %.3f %.3f), mouth (%.3f %.3f %.3f), height %.3f units\n", f->nose_tip[0],
               f->nose_tip[1], f->nose_tip[2], f->mouth[0], f->mouth[1], f->mouth[2], f->face_height);
        printf("  confidence    %.2f (symmetry %.2f, nose %.2f, eyes %.2f, mouth %.2f; a face needs %.2f)\n", f->confidence,
               f->evidence[0], f->evidence[1], f->evidence[2], f->evidence[3], RS_PACK_FACE_MIN_CONFIDENCE);
    } else if (rep->face_rejected) {
        printf("  face          rejected (its landmarks were not finite): every splat is `other`, framed by the bounds\n");
    } else if (f->confidence > 0) {
        printf("  face          not used: confidence %.2f (symmetry %.2f, nose %.2f, eyes %.2f, mouth %.2f) is under %.2f;"
               " every splat is `other`, framed by the bounds\n",
               f->confidence, f->evidence[0], f->evidence[1], f->evidence[2], f->evidence[3], RS_PACK_FACE_MIN_CONFIDENCE);
    } else {
        printf("  face          not found: every splat is `other` (see --help for the assumptions)\n");
    }
    printf("  mm_per_unit   %.4g (%s)\n", c->hdr.mm_per_unit, rep->scale_why);
    printf("  regions      ");
    for (uint32_t i = 0; i < c->hdr.region_count; i++)
        printf(" %s %.1f%%", c->hdr.regions[i].name, 100.0 * c->region_counts[i] / c->hdr.count);
    printf("%s\n", rep->regions_given ? " (some given by the input)" : "");
    if (o->maps[2]) {
        printf("  specular map  mean per region (not stored):");
        for (uint32_t i = 0; i < RS_REGION_STANDARD_COUNT; i++)
            if (!isnan(rep->specular_mean[i])) printf(" %s %.3f", c->hdr.regions[i].name, rep->specular_mean[i]);
        printf("\n");
    }
    double total = load_s + save_s;
    printf("  time          load %.2fs", load_s);
    for (int s = 0; s < RS_PACK_STEP_COUNT; s++) {
        if (rep->seconds[s] == 0) continue;
        printf(", %s %.2fs", rs_pack_step_name((rs_pack_step)s), rep->seconds[s]);
        total += rep->seconds[s];
    }
    printf(", save %.2fs; total %.2fs\n", save_s, total);
}

static int convert(options *o)
{
    rs_error err = {0};
    // Fail before the slow part when the output cannot be written at all.
    char dir[4096];
    snprintf(dir, sizeof dir, "%s", o->output);
    char *slash = strrchr(dir, '/');
    if (slash) *(slash == dir ? slash + 1 : slash) = 0;
    else snprintf(dir, sizeof dir, ".");
    if (access(dir, W_OK) != 0) return fail(1, "%s: cannot write: %s", o->output, strerror(errno));

    double t0 = rs_time_now();
    rs_import_scene *scene = NULL;
    if (rs_import_load_with(o->input, &o->import, &scene, &err) != RS_OK) return fail(1, "%s", err.msg);
    rs_ply_mesh *mesh = scene->mesh;
    snprintf(o->format, sizeof o->format, "%s", scene->format_name);
    snprintf(o->declared_unit, sizeof o->declared_unit, "%s", scene->unit_source);
    o->desc.declared_mm_per_unit = scene->declared_mm_per_unit;
    o->desc.declared_unit = o->declared_unit;
    // Shown even with -q: the file was accepted on a reading the format does not spell out.
    if (mesh->warnings[0]) {
        char w[sizeof mesh->warnings * 4];
        rs_text_sanitize(w, sizeof w, mesh->warnings, strlen(mesh->warnings));
        fprintf(stderr, "rouge-pack: warning: %s: %s\n", o->input, w);
    }
    // Maps given here are not the file's own: they are sampled with the coordinates as the file stores
    // them, t = 0 the bottom row (the PLY and OBJ convention, and three.js's for the bundled GLB), so
    // undo the flip assimp applies to glTF's top-left origin.
    bool external_maps = o->maps[0] || o->maps[1] || o->maps[2] || o->maps[3];
    if (external_maps && scene->v_flipped && mesh->uv)
        for (uint32_t i = 0; i < mesh->vertex_count; i++) mesh->uv[i][1] = 1.0f - mesh->uv[i][1];
    rs_image img[4] = {{0}};
    const rs_image **slot[4] = {&o->desc.texture, &o->desc.normal_map, &o->desc.specular_map, &o->desc.region_map};
    for (int k = 0; k < 4; k++) {
        if (!o->maps[k]) continue;
        rs_result r = k == 0 ? rs_image_load_any(o->maps[k], &img[k], &err) : rs_image_read_png(o->maps[k], &img[k], &err);
        if (r != RS_OK) {
            for (int j = 0; j < k; j++) rs_image_free(&img[j]);
            rs_import_destroy(scene);
            return fail(1, "%s: %s", map_flag[k], err.msg);
        }
        *slot[k] = &img[k];
    }
    // The materials' own colour textures, unless --texture replaces them.
    // A texture that cannot be used is a warning: the conversion goes on with vertex colours or grey.
    rs_image *pages = NULL;
    char tex_warnings[2048] = "";
    if (!o->maps[0] && rs_import_load_pages(scene, &pages, tex_warnings, sizeof tex_warnings, &err) != RS_OK) {
        for (int k = 0; k < 4; k++) rs_image_free(&img[k]);
        rs_import_destroy(scene);
        return fail(1, "%s", err.msg);
    }
    if (tex_warnings[0]) {
        char w[sizeof tex_warnings * 4];
        rs_text_sanitize(w, sizeof w, tex_warnings, strlen(tex_warnings));
        fprintf(stderr, "rouge-pack: warning: %s: %s\n", o->input, w);
    }
    uint32_t page_count = pages ? scene->page_count : 0;
    uint8_t(*wrap)[2] = page_count ? calloc(page_count, sizeof *wrap) : NULL;
    for (uint32_t i = 0; i < page_count; i++) {
        o->pages_textured += pages[i].pixels != NULL;
        if (wrap) memcpy(wrap[i], scene->pages[i].wrap, sizeof wrap[i]);
    }
    o->desc.pages = pages;
    o->desc.page_count = page_count;
    o->desc.page_wrap = (const uint8_t(*)[2])wrap;
    double load_s = rs_time_now() - t0;

    char notes[512];
    const char *base = strrchr(o->input, '/');
    snprintf(notes, sizeof notes, "converted by rouge-pack from %s", base ? base + 1 : o->input);
    o->desc.notes = notes;
    progress bar = {.on = !o->quiet && isatty(2), .last_step = -1, .last_pct = -1};
    if (bar.on) {
        o->desc.progress = show_progress;
        o->desc.progress_user = &bar;
    }
    if (mesh->texture_file && mesh->tri && !o->maps[0])
        snprintf(o->texture_hint, sizeof o->texture_hint, "%s", mesh->texture_file);
    rs_pack_report rep;
    rs_splat_cloud *cloud = NULL;
    rs_result r = rs_pack_convert(mesh, &o->desc, &cloud, &rep, &err);
    // No face in the largest component (a cube, Suzanne, a bust's base): the face defaults would drop the
    // rest of the model, so convert the whole model instead, and say so.
    bool whole = false;
    if (r == RS_OK && !rep.face.found && rep.triangles_dropped > 0 && !o->desc.all_components) {
        rs_pack_desc all = o->desc;
        all.all_components = true;
        rs_splat_destroy(cloud);
        cloud = NULL;
        r = rs_pack_convert(mesh, &all, &cloud, &rep, &err);
        whole = true;
    }
    if (bar.on) fputs("\r\033[K", stderr);
    for (int k = 0; k < 4; k++) rs_image_free(&img[k]);
    rs_import_free_pages(pages, page_count);
    free(wrap);
    o->desc.pages = NULL;
    o->desc.page_wrap = NULL;
    rs_import_destroy(scene);
    if (r != RS_OK) return fail(1, "%s: %s", o->input, err.msg);

    // The preview is drawn before anything is written, so a failure leaves no files behind.
    rs_image pv = {0};
    if (o->preview && rs_pack_preview(cloud, 512, &pv, &err) != RS_OK) {
        rs_splat_destroy(cloud);
        return fail(1, "preview: %s", err.msg);
    }
    double t1 = rs_time_now();
    r = rs_splat_save(cloud, o->output, &err);
    double save_s = rs_time_now() - t1;
    if (r == RS_OK && o->preview && rs_image_write_png(o->preview, &pv, &err) != RS_OK) {
        unlink(o->output);
        r = err.code ? err.code : RS_ERR_IO;
    }
    rs_image_free(&pv);
    if (r != RS_OK) {
        rs_splat_destroy(cloud);
        return fail(1, "%s", err.msg);
    }
    if (!o->quiet) print_summary(o, cloud, &rep, load_s, save_s);
    // Said even with -q: the scale sets the skin's scattering width, and here it is a guess.
    if (rep.scale == RS_PACK_SCALE_INFERRED || rep.scale == RS_PACK_SCALE_ESTIMATED)
        fprintf(stderr, "rouge-pack: note: %s: scale %.4g mm per unit, %s; set --units if not\n", o->input,
                cloud->hdr.mm_per_unit, rep.scale_why);
    // Said even with -q (on stderr, once the file is written): the result is not what the face defaults give.
    if (!rep.face.found) {
        char why[128];
        if (rep.face_rejected)
            snprintf(why, sizeof why, "a face was found but its frame is not finite, so it is not used");
        else if (rep.face.confidence > 0)
            snprintf(why, sizeof why, "no face (the best candidate's confidence is %.2f, under %.2f)", rep.face.confidence,
                     RS_PACK_FACE_MIN_CONFIDENCE);
        else
            snprintf(why, sizeof why, "no face found (in any orientation, nor +y up, +z forward)");
        fprintf(stderr, "rouge-pack: note: %s: %s; converted %s as a plain model, framed by its bounding box\n", o->input,
                why, whole ? "every component" : "it");
    }
    rs_splat_destroy(cloud);
    return 0;
}

int main(int argc, char **argv)
{
    options o = {0};
    const char *info_path = NULL, *ao_path = NULL;
    bool mm_given = false;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        // Flags that take a value: the value is the next argument.
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        bool takes = true;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(usage, stdout);
            return 0;
        } else if (!strcmp(a, "-q") || !strcmp(a, "--quiet")) {
            o.quiet = true;
            takes = false;
        } else if (!strcmp(a, "--all-components")) {
            o.desc.all_components = true;
            takes = false;
        } else if (!strcmp(a, "--no-ao")) {
            o.desc.no_ao = true;
            takes = false;
        } else if (!strcmp(a, "--allow-outside-paths")) {
            o.import.allow_outside_paths = true;
            takes = false;
        } else if (a[0] == '-' && a[1] != 0) {
            static const char *const known[] = {"-o", "--output", "--points", "--texture", "--normal-map",
                                                "--specular-map", "--region-map", "--mm-per-unit", "--units", "--min-lod",
                                                "--seed", "--up", "--forward", "--preview", "--info", "--ao"};
            bool ok = false;
            for (size_t k = 0; k < RS_COUNT_OF(known); k++) ok |= !strcmp(a, known[k]);
            if (!ok) return fail(2, "unknown option '%s' (see --help)", a);
        } else {
            if (o.input) return fail(2, "more than one input: '%s' and '%s'", o.input, a);
            o.input = a;
            takes = false;
        }
        if (!takes) continue;
        if (!v) return fail(2, "%s needs a value", a);
        i++;
        uint64_t n;
        if (!strcmp(a, "-o") || !strcmp(a, "--output")) o.output = v;
        else if (!strcmp(a, "--preview")) o.preview = v;
        else if (!strcmp(a, "--info")) info_path = v;
        else if (!strcmp(a, "--ao")) ao_path = v;
        else if (!strcmp(a, "--points")) {
            if (!parse_u64(v, 1, RS_SPLAT_MAX_COUNT, &n)) return fail(2, "--points: expected a count 1..%u, got '%s'", RS_SPLAT_MAX_COUNT, v);
            o.desc.points = (uint32_t)n;
        } else if (!strcmp(a, "--min-lod")) {
            if (!parse_u64(v, 1, RS_SPLAT_MAX_COUNT, &n)) return fail(2, "--min-lod: expected a count 1..%u, got '%s'", RS_SPLAT_MAX_COUNT, v);
            o.desc.min_lod = (uint32_t)n;
        } else if (!strcmp(a, "--seed")) {
            if (!parse_u64(v, 0, UINT64_MAX, &n)) return fail(2, "--seed: expected a non-negative integer, got '%s'", v);
            o.desc.seed = n;
        } else if (!strcmp(a, "--units")) {
            if (!(o.desc.mm_per_unit = rs_pack_unit_parse(v))) return fail(2, "--units: expected mm, cm, m or in, got '%s'", v);
            o.units = v;
        } else if (!strcmp(a, "--mm-per-unit")) {
            if (!parse_scale(v, &o.desc.mm_per_unit)) return fail(2, "--mm-per-unit: expected a number > 0, got '%s'", v);
            mm_given = true;
        } else if (!strcmp(a, "--up") || !strcmp(a, "--forward")) {
            rs_pack_axis ax = rs_pack_axis_parse(v);
            if (ax == RS_PACK_AXIS_DEFAULT) return fail(2, "%s: expected an axis +x -x +y -y +z -z, got '%s'", a, v);
            *(a[2] == 'u' ? &o.desc.up : &o.desc.forward) = ax;
        } else {
            for (int k = 0; k < 4; k++)
                if (!strcmp(a, map_flag[k])) o.maps[k] = v;
        }
    }
    if (info_path) {
        if (o.input || o.output) return fail(2, "--info takes only an .rsf file (and --preview)");
        return info(info_path, o.preview);
    }
    if (ao_path) {
        if (o.input || info_path || o.preview) return fail(2, "--ao takes only an .rsf file and -o OUT.rsf");
        if (!o.output) return fail(2, "no output: give -o OUT.rsf");
        return recompute_ao(ao_path, o.output, o.quiet);
    }
    if (!o.input) return fail(2, "no input scan (see --help)");
    if (o.units && mm_given) return fail(2, "--units and --mm-per-unit both give the scale: use one");
    rs_pack_axis up = o.desc.up ? o.desc.up : RS_PACK_AXIS_POS_Y, fwd = o.desc.forward ? o.desc.forward : RS_PACK_AXIS_POS_Z;
    if ((up - 1) / 2 == (fwd - 1) / 2) return fail(2, "--up and --forward must be different axes");
    if (!o.output) return fail(2, "no output: give -o OUT.rsf");
    if (is_rsf(o.input)) {
        static const rs_pack_desc none;
        if (memcmp(&o.desc, &none, sizeof none) != 0 || o.preview || o.maps[0] || o.maps[1] || o.maps[2] || o.maps[3])
            return fail(2, "%s is an .rsf file: it is rewritten as it is, conversion options do not apply", o.input);
        return rewrite(o.input, o.output, o.quiet);
    }
    return convert(&o);
}
