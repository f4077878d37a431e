// rouge_bench.c — `make bench` (tools/bench.sh runs it): measures rouge on this machine and prints one
// markdown table, the evidence the README quotes (docs/bench.md explains each row).
//
// Rows: machine and GL renderer; file bytes per splat (ours vs the float PLY's); conversion time of the
// 600k scan and of the textured mesh (rouge-pack run as a child process); load time of the 600k face;
// .rsf version 2: bytes per splat of the converted 600k scan, decode time against version 1's, time to
// the first LOD level through the progressive loader;
// brush stamp cost for sizes 0.1/0.2/0.3; bare / reference / mobile frame times at 512x512 and 1280x720
// and their ratios; mobile-vs-reference PSNR/SSIM/CIEDE2000 over 8 views x 2 lights in the diffuse and
// full modes; peak CPU memory; GPU bytes per splat; the window's frame time while orbiting.
// Every time is a median of repeated runs; frames are glFinish-timed wall times (on a real GPU that
// is the GPU frame time; on llvmpipe the CPU's). Nothing here is asserted: timings are never tests.
// A row whose input or program is missing says "n/a (why)" and the rest still runs.
//
//   build/rouge-bench --build build [--data ../shared/data] [--quick] [--face assets/face.rsf]
//                     [--only size,convert,load,rsf,stamp,memory,frames,env,paint,window,web]   (a subset of the rows)
//                     [--env-runs N]   (processes the environment rows are measured in, default 5; 1: this one)
#define _DEFAULT_SOURCE  // wait4 (per-child peak memory)

#include "bench_kernels.h"
#include "formats/env_lookup.h"
#include "makeup/makeup.h"
#include "render/render.h"
#include "splat/splat.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

// ---- the table ----

#define MAX_ROWS 64

typedef struct row {
    char what[96], value[192], notes[320];
} row;

typedef struct bench {
    const char *build, *data, *face, *tmp;
    const char *only;           // comma-separated row groups, NULL for all
    bool quick;
    int env_runs;               // separate processes the environment rows run in (1: this process)
    int frames;                 // per frame-time configuration
    row rows[MAX_ROWS];
    int row_count;
    rs_splat_cloud *cloud;
} bench;

static void add_row(bench *b, const char *what, const char *notes, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static void add_row(bench *b, const char *what, const char *notes, const char *fmt, ...)
{
    if (b->row_count >= MAX_ROWS) return;
    row *r = &b->rows[b->row_count++];
    snprintf(r->what, sizeof r->what, "%s", what);
    snprintf(r->notes, sizeof r->notes, "%s", notes ? notes : "");
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(r->value, sizeof r->value, fmt, ap);
    va_end(ap);
}

static void progress(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static void progress(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fputs("bench: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}

// Whether a row group runs: all of them unless --only names some.
static bool wanted(const bench *b, const char *group)
{
    if (!b->only) return true;
    size_t n = strlen(group);
    for (const char *p = b->only; *p;) {
        size_t len = strcspn(p, ",");
        if (len == n && strncmp(p, group, n) == 0) return true;
        p += len + (p[len] == ',');
    }
    return false;
}



static bool file_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

static long long file_size(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 ? (long long)st.st_size : -1;
}

// ---- child processes: wall time, peak memory, exit status ----

typedef struct child_result {
    bool ran;                   // started and exited on its own
    int status;                 // exit code (or 128 + signal)
    double wall_s;
    long maxrss_kb;
} child_result;

// Runs argv with stdout to out_path (or /dev/null) and stderr to /dev/null, killing it after timeout_s.
static child_result run_child(char *const argv[], const char *out_path, double timeout_s)
{
    child_result res = {0};
    double t0 = rs_time_now();
    pid_t pid = fork();
    if (pid < 0) return res;
    if (pid == 0) {
        int out = open(out_path ? out_path : "/dev/null", O_WRONLY | O_CREAT | O_TRUNC, 0644);
        int null = open("/dev/null", O_WRONLY);
        if (out >= 0) dup2(out, 1);
        if (null >= 0) dup2(null, 2);
        execv(argv[0], argv);
        _exit(127);
    }
    int status = 0;
    struct rusage ru;
    memset(&ru, 0, sizeof ru);
    for (;;) {
        pid_t w = wait4(pid, &status, WNOHANG, &ru);
        if (w == pid) break;
        if (w < 0 && errno != EINTR) return res;
        if (rs_time_now() - t0 > timeout_s) {
            kill(pid, SIGKILL);
            wait4(pid, &status, 0, &ru);
            res.status = 124;
            return res;
        }
        nanosleep(&(struct timespec){0, 5 * 1000 * 1000}, NULL);
    }
    res.wall_s = rs_time_now() - t0;
    res.ran = true;
    res.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    res.maxrss_kb = ru.ru_maxrss;
    return res;
}

// ---- machine ----

static void machine_rows(bench *b)
{
    char model[160] = "unknown CPU";
    FILE *f = fopen("/proc/cpuinfo", "r");
    if (f) {
        char line[512];
        while (fgets(line, sizeof line, f)) {
            if (strncmp(line, "model name", 10) != 0) continue;
            const char *c = strchr(line, ':');
            if (!c) continue;
            c++;
            while (*c == ' ' || *c == '\t') c++;
            snprintf(model, sizeof model, "%s", c);
            model[strcspn(model, "\n")] = 0;
            break;
        }
        fclose(f);
    }
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    double load[1] = {0};
    f = fopen("/proc/loadavg", "r");
    if (f) {
        if (fscanf(f, "%lf", &load[0]) != 1) load[0] = 0;
        fclose(f);
    }
    char notes[128];
    snprintf(notes, sizeof notes, "load average %.1f when the bench started (shared machines slow every row)",
             load[0]);
    add_row(b, "machine", notes, "%s, %ld cores", model, cores);
}

// ---- file size, conversion, load ----

// Vertex count from a PLY header ("element vertex N"), 0 when not found.
static unsigned long ply_vertex_count(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) return 0;
    char line[512];
    unsigned long n = 0;
    for (int i = 0; i < 200 && fgets(line, sizeof line, f); i++) {
        if (sscanf(line, "element vertex %lu", &n) == 1) break;
        if (!strncmp(line, "end_header", 10)) break;
    }
    fclose(f);
    return n;
}

static void size_rows(bench *b, const char *ply)
{
    long long bytes = file_size(b->face);
    uint32_t n = b->cloud->hdr.count;
    unsigned char head[8] = {0};
    FILE *f = fopen(b->face, "rb");
    if (f) {
        if (fread(head, 1, sizeof head, f) != sizeof head) head[4] = 0;
        fclose(f);
    }
    char notes[320];
    if (head[4] == 1)
        snprintf(notes, sizeof notes, ".rsf version 1: 16 B records + %.0f B header/notes/CRC", (double)bytes - 16.0 * n - 4.0);
    else
        snprintf(notes, sizeof notes, ".rsf version %u: entropy-coded chunks, coarsest LOD level first; goal <= 8 B "
                 "(issue 14)", head[4]);
    add_row(b, "file bytes/splat: ours (.rsf)", notes, "%.2f B (%s: %lld B, %u splats)", (double)bytes / n,
            b->face, bytes, n);
    unsigned long pn = ply ? ply_vertex_count(ply) : 0;
    if (!ply || pn == 0) {
        add_row(b, "file bytes/splat: float PLY", NULL, "n/a (shared data absent)");
        return;
    }
    long long pb = file_size(ply);
    snprintf(notes, sizeof notes, "binary float xyz + normal + uchar rgb; ours is %.1fx smaller",
             ((double)pb / pn) / ((double)bytes / n));
    add_row(b, "file bytes/splat: float PLY", notes, "%.2f B (head_points_600k.ply: %lld B, %lu points)",
            (double)pb / pn, pb, pn);
}

static void convert_row(bench *b, const char *what, char *const argv[], const char *out)
{
    char pack[512];
    snprintf(pack, sizeof pack, "%s/rouge-pack", b->build);
    if (!file_exists(pack)) {
        add_row(b, what, NULL, "n/a (%s not built)", pack);
        return;
    }
    int runs = b->quick ? 1 : 3;
    double wall[8];
    long rss = 0;
    for (int i = 0; i < runs; i++) {
        child_result c = run_child(argv, NULL, 300);
        if (!c.ran || c.status != 0) {
            add_row(b, what, NULL, "n/a (rouge-pack failed: exit %d)", c.status);
            return;
        }
        wall[i] = c.wall_s;
        rss = RS_MAX(rss, c.maxrss_kb);
    }
    rs_splat_cloud *c = NULL;
    rs_error err = {0};
    uint32_t count = 0;
    if (rs_splat_load(out, &c, &err) == RS_OK) count = c->hdr.count;
    rs_splat_destroy(c);
    unlink(out);
    char notes[320];
    snprintf(notes, sizeof notes, "median of %d run%s, whole process (read PLY, normals/radii, LOD order, regions, "
             "write); %u splats; peak RSS %.0f MiB", runs, runs > 1 ? "s" : "", count, rss / 1024.0);
    double med = bench_median(wall, runs);
    add_row(b, what, notes, "%.2f s", med);
}

static void convert_rows(bench *b, const char *ply)
{
    char pack[512], out[512], mesh[512], tex[512], nmap[512];
    snprintf(pack, sizeof pack, "%s/rouge-pack", b->build);
    snprintf(out, sizeof out, "%s/convert.rsf", b->tmp);
    if (!ply) {
        add_row(b, "convert 600k point cloud", NULL, "n/a (shared data absent)");
    } else {
        progress("converting the 600k point cloud");
        char *argv[] = {pack, (char *)ply, "-o", out, "-q", NULL};
        convert_row(b, "convert 600k point cloud", argv, out);
    }
    snprintf(mesh, sizeof mesh, "%s/leeperrysmith/head_mesh.ply", b->data);
    snprintf(tex, sizeof tex, "%s/leeperrysmith/color.png", b->data);
    snprintf(nmap, sizeof nmap, "%s/leeperrysmith/normal.png", b->data);
    if (!file_exists(mesh) || !file_exists(tex) || !file_exists(nmap)) {
        add_row(b, "convert textured mesh, --points 600000", NULL, "n/a (shared data absent)");
        return;
    }
    progress("converting the textured mesh at --points 600000");
    char *argv[] = {pack, mesh, "--texture", tex, "--normal-map", nmap, "--points", "600000", "-o", out, "-q", NULL};
    convert_row(b, "convert textured mesh, --points 600000", argv, out);
    // The GLB a user downloads (three.js's LeePerrySmith: its colour map beside it), through assimp, with
    // occlusion: issue 24's target is 10 s on 2 cores.
    char glb[512], col[512];
    snprintf(glb, sizeof glb, "%s/leeperrysmith/source/LeePerrySmith.glb", b->data);
    snprintf(col, sizeof col, "%s/leeperrysmith/source/Map-COL.jpg", b->data);
    if (!file_exists(glb) || !file_exists(col)) {
        add_row(b, "GLB -> .rsf, textured, --points 600000", NULL, "n/a (shared data absent)");
        return;
    }
    progress("converting the GLB at --points 600000");
    char *gargv[] = {pack, glb, "--texture", col, "--points", "600000", "-o", out, "-q", NULL};
    convert_row(b, "GLB -> .rsf, textured, --points 600000", gargv, out);
}

static void load_row(bench *b)
{
    int runs = b->quick ? 5 : 21;
    double ms[32];
    rs_error err = {0};
    for (int i = 0; i < runs; i++) {
        rs_splat_cloud *c = NULL;
        double t0 = rs_time_now();
        rs_result r = rs_splat_load(b->face, &c, &err);
        ms[i] = (rs_time_now() - t0) * 1000.0;
        rs_splat_destroy(c);
        if (r) {
            add_row(b, "load .rsf", NULL, "n/a (%s)", err.msg);
            return;
        }
    }
    char what[96], notes[160];
    snprintf(what, sizeof what, "load %uk splats (.rsf)", (b->cloud->hdr.count + 500) / 1000);
    snprintf(notes, sizeof notes, "rs_splat_load: read, CRC, validate, decode; median of %d (file in page cache)",
             runs);
    add_row(b, what, notes, "%.1f ms", bench_median(ms, runs));
}

// ---- .rsf version 2 ----

// Writes `c` as `version` to path; false (and a row saying why) on failure.
static bool write_version(bench *b, const rs_splat_cloud *c, uint32_t version, const char *path)
{
    rs_error err = {0};
    if (rs_splat_save_with(c, path, &(rs_splat_save_desc){.version = version}, &err) == RS_OK) return true;
    add_row(b, "rsf v2", NULL, "n/a (%s)", err.msg);
    return false;
}

// Median ms of rs_splat_load (file in the page cache) or, with `memory`, rs_splat_load_memory.
static double time_load(const char *path, bool memory, int runs)
{
    void *data = NULL;
    size_t len = 0;
    rs_error err = {0};
    if (memory && rs_file_read_all(path, (size_t)1 << 31, &data, &len, &err) != RS_OK) return NAN;
    double ms[64];
    runs = RS_MIN(runs, 64);
    for (int i = 0; i < runs; i++) {
        rs_splat_cloud *c = NULL;
        double t0 = rs_time_now();
        rs_result r = memory ? rs_splat_load_memory(data, len, &c, &err) : rs_splat_load(path, &c, &err);
        ms[i] = (rs_time_now() - t0) * 1000.0;
        rs_splat_destroy(c);
        if (r != RS_OK) {
            free(data);
            return NAN;
        }
    }
    free(data);
    return bench_median(ms, runs);
}

// Time from opening the file until the coarsest LOD level is decoded and a preview cloud of it exists
// (what a viewer needs before its first frame), reading 64 KiB at a time; and that level's size.
static double time_first_level(const char *path, uint32_t *level, size_t *bytes_read)
{
    double t0 = rs_time_now();
    int fd = open(path, O_RDONLY);
    if (fd < 0) return NAN;
    rs_splat_loader *l = NULL;
    rs_error err = {0};
    rs_splat_cloud *p = NULL;
    static unsigned char buf[65536];
    size_t got = 0;
    if (rs_splat_loader_create(&(rs_splat_loader_desc){.name = path}, &l, &err) == RS_OK) {
        ssize_t n;
        while (!p && (n = read(fd, buf, sizeof buf)) > 0) {
            got += (size_t)n;
            if (rs_splat_loader_feed(l, buf, (size_t)n, &err) != RS_OK) break;
            uint32_t ready = rs_splat_loader_ready(l);
            if (ready && rs_splat_loader_preview(l, ready, &p, &err) == RS_OK) *level = ready;
        }
    }
    double t = rs_time_now() - t0;
    close(fd);
    rs_splat_loader_destroy(l);
    bool ok = p != NULL;
    rs_splat_destroy(p);
    *bytes_read = got;
    return ok ? t * 1000.0 : NAN;
}

static void rsf_rows(bench *b, const char *ply)
{
    char pack[512], out[512], v1[512], v2[512], notes[320];
    snprintf(pack, sizeof pack, "%s/rouge-pack", b->build);
    snprintf(out, sizeof out, "%s/rsf2_600k.rsf", b->tmp);
    if (!ply || !file_exists(pack)) {
        add_row(b, "file bytes/splat: rouge-pack 600k scan", NULL, "n/a (%s)", ply ? "rouge-pack not built" : "shared data absent");
    } else {
        progress("converting the 600k point cloud for the .rsf v2 rows");
        char *argv[] = {pack, (char *)ply, "-o", out, "-q", NULL};
        child_result c = run_child(argv, NULL, 300);
        long long bytes = file_size(out);
        if (!c.ran || c.status != 0 || bytes <= 0) {
            add_row(b, "file bytes/splat: rouge-pack 600k scan", NULL, "n/a (rouge-pack failed: exit %d)", c.status);
        } else {
            snprintf(notes, sizeof notes, ".rsf v2 as rouge-pack writes it (10-bit normals with bent normals, 6-bit radii, AO, zstd level 17); "
                     "version 1: 16 B; goal <= 8 B (issue 14)");
            add_row(b, "file bytes/splat: rouge-pack 600k scan (.rsf v2)", notes, "%.2f B (%lld B)",
                    (double)bytes / 600000.0, bytes);
        }
        unlink(out);
    }
    // Decode and load: the bench face written both ways, timed in the same run.
    snprintf(v1, sizeof v1, "%s/face_v1.rsf", b->tmp);
    snprintf(v2, sizeof v2, "%s/face_v2.rsf", b->tmp);
    if (!write_version(b, b->cloud, 1, v1) || !write_version(b, b->cloud, 2, v2)) return;
    int runs = b->quick ? 7 : 31;
    progress(".rsf v1 / v2 decode and load");
    double m1 = time_load(v1, true, runs), m2 = time_load(v2, true, runs);
    double f1 = time_load(v1, false, runs), f2 = time_load(v2, false, runs);
    uint32_t n = b->cloud->hdr.count;
    snprintf(notes, sizeof notes, "rs_splat_load_memory, median of %d: CRCs, zstd, inverse transform, checks, float "
             "decode; version 1 (no entropy decode): %.1f ms; ratio %.2f", runs, m1, m2 / m1);
    add_row(b, "decode .rsf v2 (in memory)", notes, "%.1f ms (%uk splats, %.2f B/splat)", m2, (n + 500) / 1000,
            (double)file_size(v2) / n);
    snprintf(notes, sizeof notes, "rs_splat_load of the same face, file in page cache, median of %d; version 1: "
             "%.1f ms; ratio %.2f (goal <= 1.5)", runs, f1, f2 / f1);
    add_row(b, "load .rsf v2 file", notes, "%.1f ms", f2);
    double first[64];
    uint32_t level = 0;
    size_t read_bytes = 0;
    int k = 0;
    for (int i = 0; i < runs; i++) {
        double t = time_first_level(v2, &level, &read_bytes);
        if (t == t) first[k++] = t;
    }
    if (!k) {
        add_row(b, "time to first LOD level (.rsf v2)", NULL, "n/a (the loader failed)");
    } else {
        snprintf(notes, sizeof notes, "rs_splat_loader fed 64 KiB reads until the coarsest level (%u splats) is "
                 "decoded and a preview cloud made; %zu of %lld bytes read; median of %d", level, read_bytes,
                 file_size(v2), k);
        add_row(b, "time to first LOD level (.rsf v2)", notes, "%.2f ms", bench_median(first, k));
    }
    unlink(v1);
    unlink(v2);
}

// ---- brush stamps ----

static void stamp_rows(bench *b)
{
    enum { MAX_STAMPS = 512 };
    rs_error err = {0};
    rs_makeup *mk = NULL;
    uint32_t *cand = NULL;
    uint32_t ncand = bench_face_candidates(b->cloud, &cand);
    if (ncand == 0 || rs_makeup_create(b->cloud, NULL, &mk, &err) != RS_OK) {
        add_row(b, "stamp cost", NULL, "n/a (%s)", err.msg[0] ? err.msg : "no face splats");
        free(cand);
        return;
    }
    int stamps = b->quick ? 128 : MAX_STAMPS;
    static double us[MAX_STAMPS], touched[MAX_STAMPS];
    const float sizes[3] = {0.1f, 0.2f, 0.3f};
    for (int s = 0; s < 3; s++) {
        char what[64], notes[200];
        snprintf(what, sizeof what, "stamp cost, brush size %.1f", sizes[s]);
        if (bench_stamps(b->cloud, mk, cand, ncand, sizes[s], stamps, us, touched, &err) != RS_OK) {
            add_row(b, what, NULL, "n/a (%s)", err.msg);
            continue;
        }
        double med = bench_median(us, stamps), p90 = us[(stamps * 9) / 10];
        snprintf(notes, sizeof notes, "rs_makeup_stamp on %u splats, median of %d at face positions (p90 %.0f µs); "
                 "median %.0f splats touched; goal well under 1 ms", b->cloud->hdr.count, stamps, p90,
                 bench_median(touched, stamps));
        add_row(b, what, notes, "%.0f µs", med);
    }
    rs_makeup_destroy(mk);
    free(cand);
}

// ---- peak memory (a child process, forked before this process creates any GL context) ----

static void memory_row(bench *b)
{
    fflush(NULL);
    pid_t pid = fork();
    if (pid < 0) {
        add_row(b, "peak memory (CPU)", NULL, "n/a (fork failed)");
        return;
    }
    if (pid == 0) {
        rs_error err = {0};
        rs_splat_cloud *c = NULL;
        rs_gl_context *gl = NULL;
        rs_renderer *r = NULL;
        rs_image img = {0};
        rs_view v = rs_view_defaults();
        v.width = 1280, v.height = 720;
        rs_result res = rs_splat_load(b->face, &c, &err);
        if (!res) res = rs_gl_create(&(rs_gl_desc){0}, &gl, &err);
        if (!res) res = rs_render_create(&(rs_render_desc){.cloud = c, .caps = rs_gl_get_caps(gl)}, &r, &err);
        if (!res) res = rs_render_image(r, &v, &img, &err);
        _exit(res ? 1 : 0);  // no cleanup: the peak is what we measure
    }
    int status = 0;
    struct rusage ru;
    memset(&ru, 0, sizeof ru);
    while (wait4(pid, &status, 0, &ru) < 0 && errno == EINTR) {}
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        add_row(b, "peak memory (CPU)", NULL, "n/a (headless render failed)");
        return;
    }
    char notes[200];
    snprintf(notes, sizeof notes, "ru_maxrss of a process that loads the face and renders one 1280x720 reference "
             "frame (includes the GL driver: llvmpipe keeps its targets in CPU memory)");
    add_row(b, "peak memory (CPU)", notes, "%.0f MiB (%.0f B/splat)", ru.ru_maxrss / 1024.0,
            ru.ru_maxrss * 1024.0 / b->cloud->hdr.count);
}

// ---- frame times ----

// The bare floors: visibility + attribute + normalise only. Albedo mode has no lighting, so the renderer
// skips the shadow map and the diffusion stage (rs_render_frame_setup: lit/diffuse false). The mobile
// pipeline's floor is its own passes (its targets, its LOD) at the mobile frame's splat count; the
// reference's is every splat through the reference passes. Mobile runs first: its floor takes the
// splat count from its frame.
typedef enum { CFG_MOBILE, CFG_BARE_MOBILE, CFG_REFERENCE, CFG_BARE_REFERENCE, CFG_COUNT } frame_cfg;
static const char *const cfg_names[CFG_COUNT] = {"mobile", "bare, mobile pipeline", "reference",
                                                 "bare, reference pipeline"};

// max_splats: the mobile frame's splat count, for CFG_BARE_MOBILE.
static rs_view cfg_view(frame_cfg cfg, int w, int h, uint32_t max_splats)
{
    rs_view v = rs_view_defaults();
    v.width = w, v.height = h;
    v.pipeline = cfg == CFG_MOBILE || cfg == CFG_BARE_MOBILE ? RS_PIPELINE_MOBILE : RS_PIPELINE_REFERENCE;
    if (cfg == CFG_BARE_MOBILE || cfg == CFG_BARE_REFERENCE) {
        v.mode = RS_MODE_ALBEDO;
        v.no_shadows = true;
        if (cfg == CFG_BARE_MOBILE) v.max_splats = max_splats;
    }
    return v;
}

typedef struct frame_result {
    bool ok;
    double ms;                  // median
    rs_render_stats stats;      // of the last frame
    char err[160];
} frame_result;

// Times the configurations at one size, interleaved frame by frame so that load from other
// processes (a shared machine) slows them alike instead of whichever ran at the time. Each has its
// own renderer: the shadow map is cached per renderer while the light stays put (as when orbiting), and
// one renderer alternating pipelines (different LOD prefixes) would redraw it every frame.
static void time_frames(rs_renderer *r[CFG_COUNT], int w, int h, int frames, frame_result out[CFG_COUNT])
{
    static double ms[CFG_COUNT][64];
    rs_error err = {0};
    frames = RS_MIN(frames, 64);
    memset(out, 0, CFG_COUNT * sizeof *out);
    bool failed[CFG_COUNT] = {false};
    for (int i = -1; i < frames; i++) {  // a warm-up frame: targets, shader variants, the mobile fit
        for (int c = 0; c < CFG_COUNT; c++) {
            if (failed[c]) continue;
            rs_view v = cfg_view((frame_cfg)c, w, h, out[CFG_MOBILE].stats.splats_drawn);
            rs_render_invalidate(r[c]);  // a full frame each time (the same view would redraw nothing)
            double t0 = rs_time_now();
            if (rs_render_frame(r[c], &v, &err) != RS_OK) {
                snprintf(out[c].err, sizeof out[c].err, "%s", err.msg);
                failed[c] = true;
                continue;
            }
            glFinish();
            if (i >= 0) ms[c][i] = (rs_time_now() - t0) * 1000.0;
            out[c].stats = rs_render_get_stats(r[c]);
        }
    }
    for (int c = 0; c < CFG_COUNT; c++) {
        out[c].ok = !failed[c];
        out[c].ms = failed[c] ? NAN : bench_median(ms[c], frames);
    }
}

static void frame_rows(bench *b, rs_gl_context *gl)
{
    const int sizes[2][2] = {{512, 512}, {1280, 720}};
    rs_renderer *r[CFG_COUNT] = {NULL};
    rs_error err = {0};
    for (int c = 0; c < CFG_COUNT; c++) {
        if (rs_render_create(&(rs_render_desc){.cloud = b->cloud, .caps = rs_gl_get_caps(gl)}, &r[c], &err) == RS_OK)
            continue;
        add_row(b, "frame times", NULL, "n/a (%s)", err.msg);
        for (int k = 0; k < c; k++) rs_render_destroy(r[k]);
        return;
    }
    for (int s = 0; s < 2; s++) {
        progress("mobile / reference / bare frames at %dx%d", sizes[s][0], sizes[s][1]);
        frame_result fr[CFG_COUNT];
        time_frames(r, sizes[s][0], sizes[s][1], b->frames, fr);
        for (int c = 0; c < CFG_COUNT; c++) {
            char what[96], notes[320];
            snprintf(what, sizeof what, "frame %s, %dx%d", cfg_names[c], sizes[s][0], sizes[s][1]);
            if (!fr[c].ok) {
                add_row(b, what, NULL, "n/a (%s)", fr[c].err);
                continue;
            }
            const char *what_runs = c == CFG_BARE_MOBILE || c == CFG_BARE_REFERENCE
                                        ? "albedo mode, no shadows: visibility + attribute + normalise"
                                    : c == CFG_REFERENCE ? "full mode, reference pipeline (6 Gaussians)"
                                                         : "full mode, mobile pipeline";
            const rs_render_stats *st = &fr[c].stats;
            snprintf(notes, sizeof notes, "%s; %u splats drawn, %d diffusion levels (%u diffusion splats), %s; "
                     "median of %d", what_runs, st->splats_drawn, st->kernel_count, st->diffusion_splats,
                     st->used_points ? "point sprites" : "quads", b->frames);
            add_row(b, what, notes, "%.1f ms", fr[c].ms);
        }
        char what[96];
        double ref = fr[CFG_REFERENCE].ms, mob = fr[CFG_MOBILE].ms;
        snprintf(what, sizeof what, "ratios at %dx%d", sizes[s][0], sizes[s][1]);
        add_row(b, what, "goals (issue 5): reference/mobile >= 5x, mobile/bare <= 2.5x (each over its own floor)",
                "reference/mobile %.2fx, mobile/bare %.2fx, reference/bare %.2fx", ref / mob,
                mob / fr[CFG_BARE_MOBILE].ms, ref / fr[CFG_BARE_REFERENCE].ms);
    }
    for (int c = 0; c < CFG_COUNT; c++) rs_render_destroy(r[c]);
}

// A paint frame (issue 13): one brush stamp (blush, size 0.1, on a splat facing the camera) plus the
// frame that shows it, with the view unchanged: incremental, stages 3 and 5 inside the stamp's rectangle.
// Against a full frame of the same view and LOD (the mobile pipeline's own density at 800x600). With a
// narrow brush (eyeliner, 0.02) the stamps are the fine layer (evaluated per pixel in stage 5): the full
// frames then carry the fine stamps painted so far (up to `frames`), which is the fine layer's cost per frame.
// `masked`: kept to the product's region; a lipstick so kept is a fine stamp masked by the lips' field per
// pixel, whatever its size (its first stamp, which builds the field, is the unmeasured warm-up).
static void paint_row(bench *b, rs_gl_context *gl, const char *cosmetic, float size, bool masked, const char *what)
{
    rs_renderer *r = NULL;
    rs_makeup *mk = NULL;
    rs_error err = {0};
    bool ok = rs_render_create(&(rs_render_desc){.cloud = b->cloud, .caps = rs_gl_get_caps(gl)}, &r, &err) == RS_OK &&
              rs_makeup_create(b->cloud, NULL, &mk, &err) == RS_OK;
    rs_view v = rs_view_defaults();
    v.width = 800, v.height = 600, v.pipeline = RS_PIPELINE_MOBILE;
    static double full[64], paint[64];
    int frames = RS_MIN(b->frames, 64);
    uint32_t seed = 7, drawn = 0;
    for (int i = -1; ok && i < frames; i++) {
        rs_render_invalidate(r);
        double t0 = rs_time_now();
        ok = rs_render_frame(r, &v, &err) == RS_OK;
        glFinish();
        if (i >= 0) full[i] = (rs_time_now() - t0) * 1000.0;
        drawn = rs_render_get_stats(r).splats_drawn;
        // A stamp where the camera sees skin, inside the picture.
        uint32_t k = 0;
        float dir[3] = {0, 0, 1};
        for (int tries = 0; tries < 1000; tries++) {
            seed = seed * 1664525u + 1013904223u;
            k = (seed >> 8) % drawn;
            rs_render_view_dir(r, &v, b->cloud->pos[k], dir);
            const float *n = b->cloud->normal[k];
            float px[2];
            bool on_screen = rs_render_project(r, &v, b->cloud->pos[k], px) && px[0] > 60 && px[1] > 60 &&
                             px[0] < (float)v.width - 60 && px[1] < (float)v.height - 60;
            if (on_screen && n[0] * dir[0] + n[1] * dir[1] + n[2] * dir[2] > 0.7f) break;
        }
        rs_makeup_stamp_desc d = {.pos = {b->cloud->pos[k][0], b->cloud->pos[k][1], b->cloud->pos[k][2]},
                                  .view_dir = {dir[0], dir[1], dir[2]}, .opacity = 0.5f, .pressure = 1.0f,
                                  .radius = rs_makeup_brush_radius(&b->cloud->hdr, size),
                                  .cosmetic = rs_cosmetic_find(cosmetic), .region_mask = masked};
        t0 = rs_time_now();
        ok = ok && rs_makeup_stamp(mk, &d, NULL, &err) == RS_OK;
        rs_makeup_fine_stamp *fine = NULL;
        uint32_t nfine = 0;
        ok = ok && rs_makeup_fine_stamps(mk, &fine, &nfine, &err) == RS_OK &&
             rs_render_update_fine(r, fine, nfine, mk, &err) == RS_OK;
        free(fine);
        rs_makeup_range ranges[RS_MAKEUP_MAX_RANGES];
        uint32_t nr = rs_makeup_take_dirty(mk, ranges, RS_MAKEUP_MAX_RANGES);
        for (uint32_t j = 0; ok && j < nr; j++)
            ok = rs_render_update_makeup(r, ranges[j].lo, ranges[j].hi - ranges[j].lo,
                                         rs_makeup_records(mk) + ranges[j].lo, &err) == RS_OK;
        ok = ok && rs_render_frame(r, &v, &err) == RS_OK;
        glFinish();
        if (i >= 0) paint[i] = (rs_time_now() - t0) * 1000.0;
    }
    if (ok) {
        double p = bench_median(paint, frames), f = bench_median(full, frames);
        char notes[240];
        snprintf(notes, sizeof notes, "%s %.2f%s: one stamp + its frame (stages 3 and 5 inside the stamp's rectangle) vs "
                 "a full frame of the same view; %u splats drawn; goal (issue 13): ratio <= 0.25; median of %d",
                 cosmetic, size, masked ? " kept to its region" : "", drawn, frames);
        add_row(b, what, notes, "%.1f ms vs %.1f ms full, ratio R %.2f", p, f, p / f);
    } else {
        add_row(b, what, NULL, "n/a (%s)", err.msg);
    }
    rs_makeup_destroy(mk);
    rs_render_destroy(r);
}

// The environment-cost rows' pair of renderers: [0] lit by the default environment, [1] by the paper's
// lamp; time_stages: each stage glFinish-timed.
static bool env_pair_create(bench *b, rs_gl_context *gl, bool time_stages, rs_renderer *r[2], rs_error *err)
{
    rs_env *env = NULL;
    bool ok = rs_env_open(RS_ENV_DEFAULT, NULL, &env, err) == RS_OK;
    for (int k = 0; ok && k < 2; k++)
        ok = rs_render_create(&(rs_render_desc){.cloud = b->cloud, .caps = rs_gl_get_caps(gl), .time_stages = time_stages},
                              &r[k], err) == RS_OK;
    ok = ok && rs_render_set_env(r[0], env, err) == RS_OK;
    rs_env_destroy(env);
    return ok;
}

// A full mobile frame of the pair's renderer k, the same view for both; turn: the environment turned, or
// the lamp moved, by that many degrees.
static bool env_pair_frame(rs_renderer *r[2], int k, float turn, rs_error *err)
{
    rs_view v = rs_view_defaults();
    v.width = v.height = 512;
    v.pipeline = RS_PIPELINE_MOBILE;
    v.lighting = k == 0 ? RS_LIGHTING_ENV : RS_LIGHTING_LIGHTS;
    v.env_rotate_deg = turn;
    v.key.yaw_deg += turn;
    rs_render_invalidate(r[k]);
    return rs_render_frame(r[k], &v, err) == RS_OK;
}

// Where the environment's cost goes: the pair with each stage glFinish-timed (slower overall, so a row of
// its own), the median per stage under the environment minus under the lamp.
static void env_stage_row(bench *b, rs_gl_context *gl)
{
    const char *what = "environment cost per stage, mobile 512x512";
    rs_renderer *r[2] = {NULL, NULL};
    rs_error err = {0};
    bool ok = env_pair_create(b, gl, true, r, &err);
    static double st[2][RS_STAGE_COUNT][64];
    int frames = RS_MIN(b->frames, 64);
    for (int i = -1; ok && i < frames; i++)
        for (int k = 0; ok && k < 2; k++) {
            ok = env_pair_frame(r, k, 0.0f, &err);
            rs_render_stats s = rs_render_get_stats(r[k]);
            for (int j = 0; ok && i >= 0 && j < RS_STAGE_COUNT; j++) st[k][j][i] = s.stage_ms[j];
        }
    if (ok) {
        double d[RS_STAGE_COUNT];
        for (int j = 0; j < RS_STAGE_COUNT; j++) d[j] = bench_median(st[0][j], frames) - bench_median(st[1][j], frames);
        add_row(b, what, "environment minus lamp, median ms per stage, glFinish after each; the shadow maps are cached",
                "shadow %+.2f, visibility %+.2f, attribute %+.2f, diffusion %+.2f, composite %+.2f ms", d[0], d[1], d[2],
                d[3], d[4]);
    } else {
        add_row(b, what, NULL, "n/a (%s)", err.msg);
    }
    for (int k = 0; k < 2; k++) rs_render_destroy(r[k]);
}

// What lighting by an environment costs the mobile frame (issue 12: at most ~15%): the default
// environment against the paper's lamp, same view, two renderers timed frame by frame in turn. Then the
// same while the light turns a degree a frame (the viewer's sun dial): shadow maps and the splats'
// irradiance are redrawn every frame instead of kept.
static void env_row(bench *b, rs_gl_context *gl)
{
    const char *what = "environment cost, mobile frame 512x512";
    rs_renderer *r[2] = {NULL, NULL};
    rs_error err = {0};
    bool ok = env_pair_create(b, gl, false, r, &err);
    static double ms[2][2][64];
    int frames = RS_MIN(b->frames, 64);
    for (int turning = 0; turning < 2; turning++)
        for (int i = -1; ok && i < frames; i++)
            for (int k = 0; ok && k < 2; k++) {
                double t0 = rs_time_now();
                ok = env_pair_frame(r, k, turning ? (float)(i + 2) : 0.0f, &err);
                glFinish();
                if (i >= 0) ms[turning][k][i] = (rs_time_now() - t0) * 1000.0;
            }
    if (ok) {
        double e = bench_median(ms[0][0], frames), p = bench_median(ms[0][1], frames);
        double et = bench_median(ms[1][0], frames), pt = bench_median(ms[1][1], frames);
        char notes[300];
        snprintf(notes, sizeof notes, "environment `%s` (SH through bent cones into stage 4, prefiltered specular, coat) vs "
                 "`paper` (one lamp), lights still (shadow maps and the splats' irradiance kept); goal (issue 12): "
                 "<= ~15%% more; median of %d", RS_ENV_DEFAULT, frames);
        add_row(b, what, notes, "%.1f ms vs %.1f ms (%+.0f%%); light turning: %.1f ms vs %.1f ms (%+.0f%%)", e, p,
                (e / p - 1.0) * 100.0, et, pt, (et / pt - 1.0) * 100.0);
    } else {
        add_row(b, what, NULL, "n/a (%s)", err.msg);
    }
    for (int k = 0; k < 2; k++) rs_render_destroy(r[k]);
    if (ok) env_stage_row(b, gl);
}

// The environment rows measured in env_runs processes of this program (--only env --env-runs 1), each
// row's numbers the median over them. On the 2-core VM the environment's cost varied from one process to
// the next far more than within one (the same tree: +11 to +19 %, each run's 20 paired frames within a
// few ms of each other; the composite alone +16 to +31 ms): where the driver's and the targets' memory
// lands, it seems. One process is one draw of that; the median of five is the estimate (of three, one
// slow process in three runs moved it by 3 points: +12 % with processes at +9, +12, +21), the spread is
// printed beside it.
static void env_rows_isolated(bench *b)
{
    const char *what = "environment cost, mobile frame 512x512", *what_st = "environment cost per stage, mobile 512x512";
    enum { MAX_RUNS = 9 };
    int runs = RS_CLAMP(b->env_runs, 1, MAX_RUNS), got = 0;
    double v[4][MAX_RUNS], st[RS_STAGE_COUNT][MAX_RUNS], pct[MAX_RUNS];
    char notes[320] = "", why[160] = "no run finished";
    for (int k = 0; k < runs; k++) {
        char out[600];
        snprintf(out, sizeof out, "%s/env_run%d.md", b->tmp, k);
        char *argv[] = {"/proc/self/exe", "--build", (char *)b->build, "--face", (char *)b->face, "--tmp",
                        (char *)b->tmp, "--only", "env", "--env-runs", "1", b->quick ? "--quick" : NULL, NULL};
        child_result c = run_child(argv, out, 600);
        FILE *f = c.ran && c.status == 0 ? fopen(out, "r") : NULL;
        if (!f) {
            if (c.ran) snprintf(why, sizeof why, "run %d: exit status %d", k + 1, c.status);
            else snprintf(why, sizeof why, "run %d: %s", k + 1, c.status == 124 ? "timed out" : "did not start");
            continue;
        }
        char line[1024], note[320] = "";
        int have = 0;
        while (fgets(line, sizeof line, f)) {
            char *cell = strchr(line + 1, '|');
            if (!cell) continue;
            if (!strncmp(line, "| environment cost, mobile frame 512x512 |", 42) &&
                sscanf(cell + 1, " %lf ms vs %lf ms (%*[^)]); light turning: %lf ms vs %lf ms", &v[0][got],
                       &v[1][got], &v[2][got], &v[3][got]) == 4) {
                char *n = strchr(cell + 1, '|');
                if (n) snprintf(note, sizeof note, "%.*s", (int)strcspn(n + 2, "|") - 1, n + 2);
                have |= 1;
            } else if (!strncmp(line, "| environment cost per stage, mobile 512x512 |", 46) &&
                       sscanf(cell + 1, " shadow %lf, visibility %lf, attribute %lf, diffusion %lf, composite %lf",
                              &st[0][got], &st[1][got], &st[2][got], &st[3][got], &st[4][got]) == RS_STAGE_COUNT) {
                have |= 2;
            } else if (!strncmp(line, "| environment cost", 18) && strstr(line, "n/a")) {
                snprintf(why, sizeof why, "%.*s", (int)strcspn(cell + 2, "|") - 1, cell + 2);
            }
        }
        fclose(f);
        if (have != 3) continue;
        pct[got] = (v[0][got] / v[1][got] - 1.0) * 100.0;
        snprintf(notes, sizeof notes, "%s", note);
        got++;
    }
    if (!got) {
        add_row(b, what, NULL, "n/a (%s)", why);
        return;
    }
    // The process whose environment cost is the median one gives the row's times (medians of separately
    // drawn numerators and denominators would mix processes); the stage row is the median per stage.
    int order[MAX_RUNS], mid;
    for (int k = 0; k < got; k++) order[k] = k;
    for (int k = 1; k < got; k++)
        for (int j = k; j > 0 && pct[order[j]] < pct[order[j - 1]]; j--) {
            int t = order[j];
            order[j] = order[j - 1], order[j - 1] = t;
        }
    mid = order[got / 2];
    double ms[RS_STAGE_COUNT];
    for (int j = 0; j < RS_STAGE_COUNT; j++) ms[j] = bench_median(st[j], got);
    char each[96] = "";
    for (int k = 0, len = 0; k < got && len < (int)sizeof each - 8; k++)
        len += snprintf(each + len, sizeof each - (size_t)len, "%s%+.0f", k ? ", " : "", pct[order[k]]);
    char more[80];
    snprintf(more, sizeof more, "; the median of %d processes", got);
    if (strlen(notes) + strlen(more) < sizeof notes) strcat(notes, more);
    add_row(b, what, notes, "%.1f ms vs %.1f ms (%+.0f%%; processes %s %%); light turning: %.1f ms vs %.1f ms (%+.0f%%)",
            v[0][mid], v[1][mid], pct[mid], each, v[2][mid], v[3][mid], (v[2][mid] / v[3][mid] - 1.0) * 100.0);
    add_row(b, what_st, "environment minus lamp, median ms per stage, glFinish after each; the shadow maps are cached; "
            "per stage the median over the processes",
            "shadow %+.2f, visibility %+.2f, attribute %+.2f, diffusion %+.2f, composite %+.2f ms", ms[0], ms[1], ms[2],
            ms[3], ms[4]);
}

// Where a frame's time goes, per stage (glFinish after each stage: slower overall, so separate rows).
static void stage_rows(bench *b, rs_gl_context *gl)
{
    rs_renderer *r = NULL;
    rs_error err = {0};
    if (rs_render_create(&(rs_render_desc){.cloud = b->cloud, .caps = rs_gl_get_caps(gl), .time_stages = true}, &r,
                         &err) != RS_OK) {
        add_row(b, "stages", NULL, "n/a (%s)", err.msg);
        return;
    }
    const frame_cfg cfgs[2] = {CFG_REFERENCE, CFG_MOBILE};
    for (int j = 0; j < 2; j++) {
        frame_cfg c = cfgs[j];
        rs_view v = cfg_view(c, 512, 512, 0);
        int n = 3;  // each reference frame here costs seconds on llvmpipe
        double st[RS_STAGE_COUNT][16];
        bool ok = true;
        for (int i = -1; i < n && ok; i++) {
            // The shadow map is cached while the light stays put; nudging the light redraws it, so the
            // shadow column shows what a light move costs.
            v.key.yaw_deg += 0.5f;
            ok = rs_render_frame(r, &v, &err) == RS_OK;
            rs_render_stats s = rs_render_get_stats(r);
            for (int k = 0; ok && i >= 0 && k < RS_STAGE_COUNT; k++) st[k][i] = s.stage_ms[k];
        }
        char what[96];
        snprintf(what, sizeof what, "stages %s, 512x512", cfg_names[c]);
        if (!ok) {
            add_row(b, what, NULL, "n/a (%s)", err.msg);
            continue;
        }
        double m[RS_STAGE_COUNT];
        for (int k = 0; k < RS_STAGE_COUNT; k++) m[k] = bench_median(st[k], n);
        add_row(b, what, "median ms per stage (paper Fig. 2), glFinish after each; the light moves every frame "
                "(in the frame rows it stays put and the shadow map is cached)",
                "shadow %.1f, visibility %.1f, attribute %.1f, diffusion %.1f, composite %.1f ms", m[0], m[1], m[2],
                m[3], m[4]);
    }
    rs_render_destroy(r);
}

// ---- mobile vs reference quality ----

static void quality_rows(bench *b, rs_renderer *r)
{
    // 8 views around the front of the face x 2 key-light directions (issue 5's fixed set).
    static const float views[8][2] = {{0, 0},   {-30, 0}, {30, 0},   {-60, 5},
                                      {60, 5},  {0, 25},  {-20, -15}, {25, -10}};
    static const float lights[2][2] = {{-35, 30}, {50, 10}};
    static const float env_turns[2] = {0, 90};
    int nviews = b->quick ? 2 : 8, size = 512;
    // Diffuse under the paper's lamp (two directions); full under the default environment (turned two
    // ways), as a person sees it. Full under the lamp would repeat the diffuse row: the lamp's specular is
    // computed per pixel alike by both pipelines, so its errors are the diffuse ones to the last digit.
    const rs_render_mode modes[2] = {RS_MODE_DIFFUSE, RS_MODE_FULL};
    const char *mode_names[2] = {"diffuse, paper lamp", "full, studio environment"};
    for (int m = 0; m < 2; m++) {
        double psnr_sum = 0, ssim_sum = 0, de_sum = 0, psnr_min = INFINITY, ssim_min = INFINITY, de_max = 0;
        int n = 0, identical = 0;
        char worst[64] = "";
        rs_error err = {0};
        bool ok = true;
        if (modes[m] == RS_MODE_FULL) {
            rs_env *env = NULL;
            ok = rs_env_open(RS_ENV_DEFAULT, NULL, &env, &err) == RS_OK && rs_render_set_env(r, env, &err) == RS_OK;
            rs_env_destroy(env);
        }
        progress("quality, %s: %d views x 2 lights", mode_names[m], nviews);
        for (int l = 0; l < 2 && ok; l++) {
            for (int i = 0; i < nviews && ok; i++) {
                rs_view v = rs_view_defaults();
                v.width = v.height = size;
                v.mode = modes[m];
                v.yaw_deg = views[i][0], v.pitch_deg = views[i][1];
                v.lighting = modes[m] == RS_MODE_FULL ? RS_LIGHTING_ENV : RS_LIGHTING_LIGHTS;
                v.key.yaw_deg = lights[l][0], v.key.pitch_deg = lights[l][1];
                v.env_rotate_deg = env_turns[l];
                rs_image ref = {0}, mob = {0};
                rs_image_metrics q;
                v.pipeline = RS_PIPELINE_REFERENCE;
                ok = rs_render_image(r, &v, &ref, &err) == RS_OK;
                v.pipeline = RS_PIPELINE_MOBILE;
                if (ok) ok = rs_render_image(r, &v, &mob, &err) == RS_OK;
                if (ok) ok = rs_image_compare(&ref, &mob, 8, &q, &err) == RS_OK;
                rs_image_free(&ref);
                rs_image_free(&mob);
                if (!ok) break;
                n++;
                if (isinf(q.psnr)) identical++;
                double p = isinf(q.psnr) ? 99.0 : q.psnr;  // identical images count as 99 dB in the mean
                psnr_sum += p, ssim_sum += q.ssim, de_sum += q.delta_e;
                if (p < psnr_min) {
                    psnr_min = p;
                    snprintf(worst, sizeof worst, "yaw %g pitch %g, %s %d", views[i][0], views[i][1],
                             modes[m] == RS_MODE_FULL ? "turn" : "light", l + 1);
                }
                ssim_min = fmin(ssim_min, q.ssim);
                de_max = fmax(de_max, q.delta_e);
            }
        }
        rs_render_set_env(r, NULL, &err);
        char what[96], notes[320];
        snprintf(what, sizeof what, "mobile vs reference, %s, %dx%d", mode_names[m], size, size);
        if (!ok) {
            add_row(b, what, NULL, "n/a (%s)", err.msg);
            continue;
        }
        snprintf(notes, sizeof notes, "%d views x %s; worst view: %s; goals: mean PSNR >= 38 dB, every view "
                 ">= 34, SSIM >= 0.97, mean ΔE <= 1.5%s", nviews,
                 modes[m] == RS_MODE_FULL ? "2 environment turns (0, 90 deg)" : "2 lamp directions", worst,
                 identical == n ? "; IDENTICAL images: the mobile pipeline draws what the reference does" : "");
        add_row(b, what, notes, "PSNR mean %.2f / worst %.2f dB, SSIM mean %.5f / worst %.5f, ΔE00 mean %.3f / "
                "worst %.3f", psnr_sum / n, psnr_min, ssim_sum / n, ssim_min, de_sum / n, de_max);
    }
}

static void gpu_row(bench *b, rs_renderer *r)
{
    rs_view v = cfg_view(CFG_REFERENCE, 1280, 720, 0);
    rs_error err = {0};
    if (rs_render_frame(r, &v, &err) != RS_OK) {
        add_row(b, "GPU bytes/splat", NULL, "n/a (%s)", err.msg);
        return;
    }
    rs_render_stats s = rs_render_get_stats(r);
    uint32_t n = b->cloud->hdr.count;
    size_t records = (size_t)n * (sizeof(rs_splat_packed) + sizeof(rs_makeup_gpu));
    char notes[256];
    snprintf(notes, sizeof notes, "buffers: %zu B splat record + %zu B makeup record per splat; with every render "
             "target at 1280x720 (rs_render_stats.gpu_bytes = %.1f MiB)", sizeof(rs_splat_packed),
             sizeof(rs_makeup_gpu), s.gpu_bytes / 1048576.0);
    add_row(b, "GPU bytes/splat", notes, "%.0f B in buffers, %.1f B with targets", (double)records / n,
            (double)s.gpu_bytes / n);
}

// ---- the window (rouge view --bench-orbit) ----

static void window_row(bench *b)
{
    const char *what = "window frame, 800x600, orbiting";
    char rouge[512], out[512], help[512];
    snprintf(rouge, sizeof rouge, "%s/rouge", b->build);
    snprintf(out, sizeof out, "%s/orbit.txt", b->tmp);
    snprintf(help, sizeof help, "%s/help.txt", b->tmp);
    if (!file_exists(rouge)) {
        add_row(b, what, NULL, "n/a (%s not built)", rouge);
        return;
    }
    if (!getenv("DISPLAY") && !getenv("WAYLAND_DISPLAY")) {
        add_row(b, what, NULL, "n/a (no display: tools/bench.sh starts Xvfb when it is installed)");
        return;
    }
    // Only a viewer that has the option: older builds would open a window and wait for a person.
    char *hargv[] = {rouge, "--help", NULL};
    run_child(hargv, help, 10);
    FILE *f = fopen(help, "r");
    bool has = false;
    char line[512];
    while (f && fgets(line, sizeof line, f)) has = has || strstr(line, "--bench-orbit");
    if (f) fclose(f);
    if (!has) {
        add_row(b, what, NULL, "n/a (this rouge has no --bench-orbit)");
        return;
    }
    progress("viewer orbit at 800x600");
    char frames[16];
    snprintf(frames, sizeof frames, "%d", b->quick ? 10 : 30);
    char *argv[] = {rouge, "view", (char *)b->face, "--size", "800x600", "--bench-orbit", frames, NULL};
    child_result c = run_child(argv, out, 300);
    f = fopen(out, "r");
    char result[512] = "";
    while (f && fgets(line, sizeof line, f))
        if (strstr(line, "bench-orbit:")) snprintf(result, sizeof result, "%s", line);
    if (f) fclose(f);
    double med = 0;
    const char *m = strstr(result, "median ");
    if (!c.ran || c.status != 0 || !m || sscanf(m, "median %lf", &med) != 1) {
        add_row(b, what, NULL, "n/a (rouge view --bench-orbit failed: exit %d)", c.status);
        return;
    }
    result[strcspn(result, "\n")] = 0;
    const char *detail = strchr(result, ':');
    add_row(b, what, detail ? detail + 2 : result, "%.1f ms", med);
}

// ---- the web build (make web): wasm vs native, the first LOD level in a browser, page weight ----

// Reads "key value..." lines a child printed into `path`; the value of `key` (NAN when absent).
static double child_value(const char *path, const char *key)
{
    FILE *f = fopen(path, "r");
    if (!f) return NAN;
    char line[256];
    double v = NAN;
    size_t n = strlen(key);
    while (fgets(line, sizeof line, f))
        if (!strncmp(line, key, n) && line[n] == ' ') v = strtod(line + n + 1, NULL);
    fclose(f);
    return v;
}

// Bytes of a file after gzip -9 (what a static host serves compressed); -1 when it cannot be measured.
static long long gzip_size(const bench *b, const char *file)
{
    char out[512], cmd[1200];
    snprintf(out, sizeof out, "%s/gzip.txt", b->tmp);
    snprintf(cmd, sizeof cmd, "gzip -9c '%s' | wc -c", file);
    char *argv[] = {"/bin/sh", "-c", cmd, NULL};
    child_result c = run_child(argv, out, 60);
    if (!c.ran || c.status) return -1;
    FILE *f = fopen(out, "r");
    long long n = -1;
    if (f && fscanf(f, "%lld", &n) != 1) n = -1;
    if (f) fclose(f);
    return n;
}

static void web_rows(bench *b)
{
    char native[512], wasm[512], out[512], node[64] = "/usr/bin/node";
    snprintf(native, sizeof native, "%s/rouge-cpubench", b->build);
    snprintf(wasm, sizeof wasm, "%s/web-bench/cpubench.js", b->build);
    snprintf(out, sizeof out, "%s/cpubench.txt", b->tmp);
    if (!file_exists(node)) snprintf(node, sizeof node, "/usr/local/bin/node");
    if (!file_exists(wasm) || !file_exists(node)) {
        add_row(b, "wasm / native, CPU work", NULL, "n/a (make web not run, or no node)");
        return;
    }
    progress("the same CPU work natively and as WebAssembly (node)");
    // Interleaved runs, so a busy moment of the machine hits both alike; medians of the per-run medians.
    enum { RUNS = 5 };
    double dn[RUNS], dw[RUNS], sn[RUNS], sw[RUNS];
    int runs = b->quick ? 2 : RUNS;
    for (int i = 0; i < runs; i++) {
        char *an[] = {native, (char *)b->face, "5", NULL}, *aw[] = {node, wasm, (char *)b->face, "5", NULL};
        child_result c = run_child(an, out, 120);
        dn[i] = child_value(out, "decode_ms"), sn[i] = child_value(out, "stamp_us");
        child_result w = run_child(aw, out, 300);
        dw[i] = child_value(out, "decode_ms"), sw[i] = child_value(out, "stamp_us");
        if (!c.ran || c.status || !w.ran || w.status) {
            add_row(b, "wasm / native, CPU work", NULL, "n/a (rouge-cpubench failed: exit %d / %d)", c.status, w.status);
            return;
        }
    }
    double mdn = bench_median(dn, runs), mdw = bench_median(dw, runs), msn = bench_median(sn, runs),
           msw = bench_median(sw, runs);
    add_row(b, "wasm / native, .rsf v2 decode", "rouge-cpubench: rs_splat_load_memory of the bundled face, native vs "
            "emcc -O3 under node, same run; goal <= 1.5x", "%.2fx (%.1f / %.1f ms)", mdw / mdn, mdw, mdn);
    add_row(b, "wasm / native, brush stamp", "rouge-cpubench: rs_makeup_stamp, blush size 0.2, 256 stamps; goal <= 1.5x",
            "%.2fx (%.0f / %.0f µs)", msw / msn, msw, msn);

    // The first LOD level in Chromium (SwiftShader): the page streams the face from a loopback server that
    // sends it at about 1.5 MB/s (tests/web/run.mjs --bench).
    char script[512];
    snprintf(script, sizeof script, "tests/web/run.mjs");
    if (file_exists(script) && file_exists("/usr/bin/chromium")) {
        progress("the first LOD level in Chromium");
        char *argv[] = {node, script, (char *)b->build, "--bench", NULL};
        child_result c = run_child(argv, out, 300);
        FILE *f = fopen(out, "r");
        double v[4] = {NAN, NAN, NAN, NAN};
        char line[256];
        while (f && fgets(line, sizeof line, f))
            if (sscanf(line, "web_first_lod %lf %lf %lf %lf", &v[0], &v[1], &v[2], &v[3]) == 4) break;
        if (f) fclose(f);
        if (!c.ran || c.status || isnan(v[3]))
            add_row(b, "web: first LOD level drawn", NULL, "n/a (browser run failed: exit %d)", c.status);
        else
            add_row(b, "web: first LOD level drawn", "Chromium + SwiftShader, 224x224 page, face streamed at ~1.5 MB/s "
                    "over loopback; then the whole face", "after %.0f KB, %.0f ms (whole face: %.1f MB, %.0f ms)",
                    v[0] / 1024, v[1], v[2] / 1048576, v[3]);
    }
    const char *page[] = {"rouge_core.wasm", "rouge_core.js", "rouge.js", "app.js", "index.html", "style.css"};
    long long total = 0, raw = 0;
    for (size_t i = 0; i < RS_COUNT_OF(page); i++) {
        char file[512];
        snprintf(file, sizeof file, "%s/web/%s", b->build, page[i]);
        long long z = gzip_size(b, file);
        if (z < 0) {
            add_row(b, "web: page weight", NULL, "n/a (%s missing)", file);
            return;
        }
        total += z, raw += file_size(file);
    }
    char face[512], notes[256];
    snprintf(face, sizeof face, "%s/web/face.rsf", b->build);
    snprintf(notes, sizeof notes, "rouge_core.wasm + .js, rouge.js, app.js, index.html, style.css; besides the face "
             "(%.1f MB) and environments; goal <= 400 KB", (double)file_size(face) / 1048576.0);
    add_row(b, "web: page weight (gzip -9)", notes, "%.0f KB (%.0f KB uncompressed)", total / 1024.0, raw / 1024.0);
}

// ---- main ----

static void print_table(const bench *b, FILE *f)
{
    fprintf(f, "| measure | value | notes |\n|---|---|---|\n");
    for (int i = 0; i < b->row_count; i++)
        fprintf(f, "| %s | %s | %s |\n", b->rows[i].what, b->rows[i].value, b->rows[i].notes);
}

static int usage(void)
{
    fprintf(stderr, "usage: rouge-bench --build DIR [--data DIR] [--face FILE.rsf] [--tmp DIR] [--quick] "
                    "[--out FILE.md]\n"
                    "                   [--only size,convert,load,rsf,stamp,memory,frames,env,paint,window,web] [--env-runs 1..9]\n");
    return 2;
}

int main(int argc, char **argv)
{
    bench *b = calloc(1, sizeof *b);
    if (!b) return 1;
    const char *out_md = NULL;
    b->build = "build";
    b->face = "assets/face.rsf";
    b->data = getenv("RS_SHARED_DATA") && *getenv("RS_SHARED_DATA") ? getenv("RS_SHARED_DATA") : "../shared/data";
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--quick")) b->quick = true;
        else if (!v) return usage();
        else if (!strcmp(a, "--build")) b->build = v, i++;
        else if (!strcmp(a, "--data")) b->data = v, i++;
        else if (!strcmp(a, "--face")) b->face = v, i++;
        else if (!strcmp(a, "--tmp")) b->tmp = v, i++;
        else if (!strcmp(a, "--out")) out_md = v, i++;
        else if (!strcmp(a, "--only")) b->only = v, i++;
        else if (!strcmp(a, "--env-runs")) {
            char *end;
            long n = strtol(v, &end, 10);
            if (*end || n < 1 || n > 9) return usage();
            b->env_runs = (int)n, i++;
        }
        else return usage();
    }
    char tmp[512];
    if (!b->tmp) {
        snprintf(tmp, sizeof tmp, "%s/bench", b->build);
        b->tmp = tmp;
    }
    mkdir(b->tmp, 0755);
    b->frames = b->quick ? 5 : 20;  // issue 5: >= 20 frames
    if (!b->env_runs) b->env_runs = b->quick ? 1 : 5;

    rs_error err = {0};
    if (rs_splat_load(b->face, &b->cloud, &err) != RS_OK) {
        fprintf(stderr, "rouge-bench: %s\n", err.msg);
        return 1;
    }
    char ply_path[512];
    snprintf(ply_path, sizeof ply_path, "%s/leeperrysmith/head_points_600k.ply", b->data);
    const char *ply = file_exists(ply_path) ? ply_path : NULL;

    machine_rows(b);
    int gl_row = -1;
    bool gl_rows = wanted(b, "frames") || wanted(b, "env") || wanted(b, "paint");
    if (gl_rows) {
        gl_row = b->row_count;
        add_row(b, "GL renderer", NULL, "n/a");  // filled in once the context exists
    }
    if (wanted(b, "size")) size_rows(b, ply);
    if (wanted(b, "convert")) convert_rows(b, ply);
    if (wanted(b, "load")) load_row(b);
    if (wanted(b, "rsf")) rsf_rows(b, ply);
    if (wanted(b, "stamp")) {
        progress("brush stamps");
        stamp_rows(b);
    }
    if (wanted(b, "memory")) {
        progress("peak memory");
        memory_row(b);  // before this process has a GL context (fork)
    }
    if (gl_rows) {
        rs_gl_context *gl = NULL;
        rs_renderer *r = NULL;
        if (rs_gl_create(&(rs_gl_desc){0}, &gl, &err) != RS_OK ||
            rs_render_create(&(rs_render_desc){.cloud = b->cloud, .caps = rs_gl_get_caps(gl)}, &r, &err) != RS_OK) {
            snprintf(b->rows[gl_row].value, sizeof b->rows[gl_row].value, "n/a (%s)", err.msg);
            add_row(b, "frame times, quality, GPU bytes", NULL, "n/a (no GLES 3 context)");
        } else {
            const rs_gl_caps *caps = rs_gl_get_caps(gl);
            snprintf(b->rows[gl_row].value, sizeof b->rows[gl_row].value, "%s", caps->renderer);
            snprintf(b->rows[gl_row].notes, sizeof b->rows[gl_row].notes, "%s, %s; float targets %s",
                     caps->platform, caps->version, caps->float_rt ? "yes" : "no");
            if (wanted(b, "frames")) frame_rows(b, gl);
            if (wanted(b, "env")) {
                progress("environment cost%s", b->env_runs > 1 ? " (in separate processes)" : "");
                if (b->env_runs > 1) env_rows_isolated(b);
                else env_row(b, gl);
            }
            if (wanted(b, "paint")) {
                progress("paint frames");
                paint_row(b, gl, "blush", 0.1f, false, "paint frame, mobile 800x600");
                paint_row(b, gl, "eyeliner", 0.02f, false, "paint frame, fine layer (liner), mobile 800x600");
                paint_row(b, gl, "lipstick_matte", 0.05f, true, "paint frame, fine layer (lipstick kept to the lips), mobile 800x600");
            }
            if (wanted(b, "frames")) {
                progress("per-stage timings");
                stage_rows(b, gl);
                quality_rows(b, r);
                gpu_row(b, r);
            }
        }
        rs_render_destroy(r);
        rs_gl_destroy(gl);
    }
    if (wanted(b, "window")) window_row(b);
    if (wanted(b, "web")) web_rows(b);

    print_table(b, stdout);
    if (out_md) {
        FILE *f = fopen(out_md, "w");
        if (f) print_table(b, f), fclose(f);
    }
    rs_splat_destroy(b->cloud);
    free(b);
    return 0;
}
