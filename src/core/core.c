// core.c — see core.h.
#define _POSIX_C_SOURCE 200809L
#include "core/core.h"

#include <errno.h>
#include <fcntl.h>
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
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->msg, sizeof err->msg, fmt, ap);
        va_end(ap);
        err->code = code;
    }
    return code;
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

rs_result rs_file_write_atomic(const char *path, const void *data, size_t len, rs_error *err)
{
    // Only ever replace a regular file: renaming over /dev/null, a FIFO or a socket would destroy it.
    struct stat st;
    if (lstat(path, &st) == 0 && !S_ISREG(st.st_mode))
        return rs_fail(err, RS_ERR_IO, "%s: cannot write: not a regular file", path);
    char tmp[4096];
    int n = snprintf(tmp, sizeof tmp, "%s.tmp.%ld", path, (long)getpid());
    if (n < 0 || (size_t)n >= sizeof tmp) return rs_fail(err, RS_ERR_ARG, "%s: path too long", path);
    int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0) return rs_fail(err, RS_ERR_IO, "%s: cannot write: %s", path, strerror(errno));
    const unsigned char *p = data;
    size_t done = 0;
    while (done < len) {
        ssize_t w = write(fd, p + done, len - done);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) {
            int e = errno;
            close(fd);
            unlink(tmp);
            return rs_fail(err, RS_ERR_IO, "%s: write failed: %s", path, strerror(e));
        }
        done += (size_t)w;
    }
    if (fsync(fd) != 0 || close(fd) != 0) {
        int e = errno;
        unlink(tmp);
        return rs_fail(err, RS_ERR_IO, "%s: write failed: %s", path, strerror(e));
    }
    if (rename(tmp, path) != 0) {
        int e = errno;
        unlink(tmp);
        return rs_fail(err, RS_ERR_IO, "%s: cannot replace: %s", path, strerror(e));
    }
    return RS_OK;
}

double rs_time_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}
