// core.c — see core.h.
// _GNU_SOURCE: O_TMPFILE (Linux); everything else used is POSIX.1-2008.
#define _GNU_SOURCE
#include "core/core.h"

#include <ctype.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <float.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

rs_result rs_fail(rs_error *err, rs_result code, const char *fmt, ...)
{
    if (err) {
        char raw[sizeof err->msg];
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(raw, sizeof raw, fmt, ap);
        va_end(ap);
        rs_text_sanitize(err->msg, sizeof err->msg, raw, strlen(raw));
        err->code = code;
    }
    return code;
}

// Length of the valid UTF-8 sequence at s (1..4), or 0 when it is not one (overlong, surrogate, cut).
static size_t utf8_seq(const unsigned char *s, size_t len, uint32_t *cp)
{
    unsigned char c = s[0];
    size_t n = c >= 0xF0 && c <= 0xF4 ? 4 : c >= 0xE0 ? 3 : c >= 0xC2 && c <= 0xDF ? 2 : 0;
    if (c >= 0xF5 || n == 0 || n > len) return 0;
    uint32_t v = c & (0xFF >> (n + 1));
    for (size_t i = 1; i < n; i++) {
        if ((s[i] & 0xC0) != 0x80) return 0;
        v = v << 6 | (s[i] & 0x3F);
    }
    static const uint32_t min[5] = {0, 0, 0x80, 0x800, 0x10000};
    if (v < min[n] || v > 0x10FFFF || (v >= 0xD800 && v <= 0xDFFF)) return 0;
    *cp = v;
    return n;
}

static bool unsafe_codepoint(uint32_t cp)
{
    return (cp >= 0x80 && cp <= 0x9F) || cp == 0x200E || cp == 0x200F || (cp >= 0x202A && cp <= 0x202E) ||
           (cp >= 0x2066 && cp <= 0x2069);
}

size_t rs_text_sanitize(char *dst, size_t cap, const char *src, size_t len)
{
    if (cap == 0) return 0;
    const unsigned char *s = (const unsigned char *)src;
    size_t o = 0;
    for (size_t i = 0; i < len && s[i];) {
        char esc[16];
        size_t n = 1, w;
        uint32_t cp = s[i];
        if (s[i] < 0x80) {
            if (s[i] < 0x20 || s[i] == 0x7F) w = (size_t)snprintf(esc, sizeof esc, "\\x%02x", s[i]);
            else esc[0] = (char)s[i], w = 1;
        } else if ((n = utf8_seq(s + i, len - i, &cp)) == 0) {
            n = 1;
            w = (size_t)snprintf(esc, sizeof esc, "\\x%02x", s[i]);
        } else if (unsafe_codepoint(cp)) {
            w = (size_t)snprintf(esc, sizeof esc, "\\u{%04x}", cp);
        } else {
            memcpy(esc, s + i, n);
            w = n;
        }
        if (o + w >= cap) break;
        memcpy(dst + o, esc, w);
        o += w;
        i += n;
    }
    dst[o] = 0;
    return o;
}

const char *rs_result_name(rs_result r)
{
    switch (r) {
    case RS_OK: return "ok";
    case RS_ERR_IO: return "I/O error";
    case RS_ERR_FORMAT: return "format error";
    case RS_ERR_LIMIT: return "limit exceeded";
    case RS_ERR_NOMEM: return "out of memory";
    case RS_ERR_GL: return "GL error";
    case RS_ERR_ARG: return "bad argument";
    }
    return "unknown error";
}

bool rs_size_mul(size_t a, size_t b, size_t *out)
{
    if (a != 0 && b > SIZE_MAX / a) return false;
    *out = a * b;
    return true;
}

bool rs_size_add(size_t a, size_t b, size_t *out)
{
    if (b > SIZE_MAX - a) return false;
    *out = a + b;
    return true;
}

void *rs_alloc_array(size_t count, size_t elem_size)
{
    size_t n;
    if (!rs_size_mul(count, elem_size, &n)) return NULL;
    return malloc(n ? n : 1);
}

rs_result rs_file_read_all(const char *path, size_t max_bytes, void **out_data, size_t *out_len, rs_error *err)
{
    // O_NONBLOCK: opening a FIFO for reading blocks until a writer appears; the type check below refuses it.
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return rs_fail(err, RS_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    struct stat st;
    if (fstat(fd, &st) != 0) {
        close(fd);
        return rs_fail(err, RS_ERR_IO, "%s: cannot stat: %s", path, strerror(errno));
    }
    // Regular files only: a directory, /dev/zero or a FIFO would hang or never end.
    if (!S_ISREG(st.st_mode)) {
        close(fd);
        return rs_fail(err, RS_ERR_IO, "%s: not a regular file", path);
    }
    if ((uint64_t)st.st_size > (uint64_t)max_bytes) {
        close(fd);
        return rs_fail(err, RS_ERR_LIMIT, "%s: file is %lld bytes, more than the %zu allowed", path,
                       (long long)st.st_size, max_bytes);
    }
    size_t len = (size_t)st.st_size;
    unsigned char *data = malloc(len ? len : 1);
    if (!data) {
        close(fd);
        return rs_fail(err, RS_ERR_NOMEM, "%s: out of memory for %zu bytes", path, len);
    }
    size_t got = 0;
    while (got < len) {
        ssize_t r = read(fd, data + got, len - got);
        if (r < 0 && errno == EINTR) continue;
        if (r <= 0) {
            free(data);
            close(fd);
            return rs_fail(err, RS_ERR_IO, "%s: read failed at byte %zu: %s", path, got,
                           r < 0 ? strerror(errno) : "file shrank while reading");
        }
        got += (size_t)r;
    }
    close(fd);
    *out_data = data;
    *out_len = len;
    return RS_OK;
}

// Splits path into its directory ("." when none) and base name.
static bool split_path(const char *path, char *dir, size_t cap, const char **base)
{
    const char *slash = strrchr(path, '/');
    *base = slash ? slash + 1 : path;
    int n = slash ? snprintf(dir, cap, "%.*s", (int)(slash - path > 0 ? slash - path : 1), path)
                  : snprintf(dir, cap, ".");
    return n > 0 && (size_t)n < cap;
}

// Removes "<base>.tmp.<pid>" files next to the target whose writer process is gone: what a save killed
// mid-write (SIGKILL, power loss) left behind. Only our own pattern, only for this target.
static void remove_stale_temps(const char *dir, const char *base)
{
    DIR *d = opendir(dir);
    if (!d) return;
    size_t bl = strlen(base);
    struct dirent *e;
    while ((e = readdir(d))) {
        const char *n = e->d_name;
        if (strncmp(n, base, bl) != 0 || strncmp(n + bl, ".tmp.", 5) != 0) continue;
        char *endp;
        long pid = strtol(n + bl + 5, &endp, 10);
        if (*endp || pid <= 0 || (pid == (long)getpid())) continue;
        if (kill((pid_t)pid, 0) == 0 || errno != ESRCH) continue;  // alive (or not ours to judge)
        char full[4096];
        if ((size_t)snprintf(full, sizeof full, "%s/%s", dir, n) < sizeof full) unlink(full);
    }
    closedir(d);
}

static bool write_all(int fd, const void *data, size_t len)
{
    const unsigned char *p = data;
    size_t done = 0;
    while (done < len) {
        ssize_t w = write(fd, p + done, len - done);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) {
            if (w == 0) errno = EIO;
            return false;
        }
        done += (size_t)w;
    }
    return true;
}

bool rs_file_id_of(const char *path, rs_file_id *out)
{
    struct stat st;
    if (!path || stat(path, &st) != 0) return false;
    *out = (rs_file_id){(uint64_t)st.st_dev, (uint64_t)st.st_ino};
    return true;
}

bool rs_file_is(const char *path, const rs_file_id *id)
{
    rs_file_id f;
    return id && rs_file_id_of(path, &f) && f.dev == id->dev && f.ino == id->ino;
}

bool rs_same_file(const char *a, const char *b)
{
    rs_file_id ib;
    return rs_file_id_of(b, &ib) && rs_file_is(a, &ib);
}

rs_result rs_file_write_atomic(const char *path, const void *data, size_t len, rs_error *err)
{
    // Only ever replace a regular file: renaming over /dev/null, a FIFO or a socket would destroy it.
    struct stat st;
    if (lstat(path, &st) == 0 && !S_ISREG(st.st_mode))
        return rs_fail(err, RS_ERR_IO, "%s: cannot write: not a regular file", path);
    char dir[4096], tmp[4096];
    const char *base;
    int n = snprintf(tmp, sizeof tmp, "%s.tmp.%ld", path, (long)getpid());
    if (n < 0 || (size_t)n >= sizeof tmp || !split_path(path, dir, sizeof dir, &base))
        return rs_fail(err, RS_ERR_ARG, "%s: path too long", path);
    remove_stale_temps(dir, base);
    // Where the filesystem has O_TMPFILE the data is written to an unnamed file, so a process killed
    // while writing leaves nothing behind; it gets the temp name only once complete, just before the rename.
    bool named = false;
#ifdef O_TMPFILE
    int fd = open(dir, O_TMPFILE | O_WRONLY | O_CLOEXEC, 0644);
#else
    int fd = -1;
#endif
    if (fd < 0) {
        fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
        named = true;
    }
    if (fd < 0) return rs_fail(err, RS_ERR_IO, "%s: cannot write: %s", path, strerror(errno));
    if (!write_all(fd, data, len) || fsync(fd) != 0) {
        int e = errno;
        close(fd);
        if (named) unlink(tmp);
        return rs_fail(err, RS_ERR_IO, "%s: write failed: %s", path, strerror(e));
    }
    if (!named) {
        char proc[64];
        snprintf(proc, sizeof proc, "/proc/self/fd/%d", fd);
        unlink(tmp);  // a stale one of our own pid (pid reuse) would make linkat fail
        if (linkat(AT_FDCWD, proc, AT_FDCWD, tmp, AT_SYMLINK_FOLLOW) != 0) {
            int e = errno;
            close(fd);
            return rs_fail(err, RS_ERR_IO, "%s: cannot write: %s", path, strerror(e));
        }
    }
    if (close(fd) != 0) {
        int e = errno;
        unlink(tmp);
        return rs_fail(err, RS_ERR_IO, "%s: write failed: %s", path, strerror(e));
    }
    if (rename(tmp, path) != 0) {
        int e = errno;
        unlink(tmp);
        return rs_fail(err, RS_ERR_IO, "%s: cannot replace: %s", path, strerror(e));
    }
    // The rename is durable only once the directory entry is on disk.
    int dfd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd >= 0) {
        fsync(dfd);
        close(dfd);
    }
    return RS_OK;
}

float rs_srgb_to_linear(float c)
{
    return c <= 0.04045f ? c / 12.92f : powf((c + 0.055f) / 1.055f, 2.4f);
}

float rs_linear_to_srgb(float c)
{
    c = c > 0.0f ? (c < 1.0f ? c : 1.0f) : 0.0f;
    return c <= 0.0031308f ? c * 12.92f : 1.055f * powf(c, 1.0f / 2.4f) - 0.055f;
}

double rs_time_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

float rs_lef32_get(const uint8_t *p)
{
    uint32_t u = rs_le32_get(p);
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

void rs_lef32_put(uint8_t *p, float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    rs_le32_put(p, u);
}

bool rs_parse_number(const char *s, double lo, double hi, double *out)
{
    if (!s || !*s || isspace((unsigned char)*s)) return false;
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (end == s || *end || errno == ERANGE || !isfinite(v) || v < lo || v > hi) return false;
    *out = v;
    return true;
}

bool rs_parse_float(const char *s, float *out)
{
    double v;
    if (!rs_parse_number(s, -FLT_MAX, FLT_MAX, &v)) return false;
    *out = (float)v;
    return true;
}

bool rs_parse_list(const char *s, char sep, int n, double lo, double hi, double *out)
{
    char tok[64];
    for (int k = 0; k < n; k++) {
        const char *end = k + 1 < n ? strchr(s, sep) : s + strlen(s);
        if (!end || (size_t)(end - s) >= sizeof tok) return false;
        memcpy(tok, s, (size_t)(end - s));
        tok[end - s] = 0;
        if (!rs_parse_number(tok, lo, hi, &out[k])) return false;
        s = end + 1;
    }
    return true;
}

bool rs_array_grow(void **ptr, uint32_t *cap, uint32_t need, size_t elem)
{
    if (need <= *cap) return true;
    uint64_t c = RS_MAX((uint64_t)*cap * 2, 64u);
    while (c < need) c *= 2;
    size_t bytes;
    if (c > UINT32_MAX || !rs_size_mul((size_t)c, elem, &bytes)) return false;
    void *q = realloc(*ptr, bytes);
    if (!q) return false;
    *ptr = q;
    *cap = (uint32_t)c;
    return true;
}
