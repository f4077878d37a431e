// textfile.c — see textfile.h.
#define _POSIX_C_SOURCE 200809L  // strtok_r
#include "formats/textfile.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

bool rs_text_next_line(rs_text_reader *t, char *buf, size_t cap, char **line, rs_result *res, rs_error *err)
{
    while (t->pos < t->len) {
        t->line++;
        const char *start = t->data + t->pos;
        const char *nl = memchr(start, '\n', t->len - t->pos);
        size_t n = nl ? (size_t)(nl - start) : t->len - t->pos;
        t->pos += n + (nl ? 1 : 0);
        if (n > 0 && start[n - 1] == '\r') n--;
        if (n > cap - 1) {
            *res = rs_fail(err, RS_ERR_FORMAT, "line %u: longer than %zu bytes", t->line, cap - 1);
            return false;
        }
        if (memchr(start, '\0', n)) {
            *res = rs_fail(err, RS_ERR_FORMAT, "line %u: NUL byte", t->line);
            return false;
        }
        memcpy(buf, start, n);
        buf[n] = '\0';
        char *l = buf + strspn(buf, " \t");
        if (*l == '\0' || *l == '#') continue;
        *line = l;
        return true;
    }
    return false;
}

rs_result rs_text_check_header(char *line, const char *magic, uint32_t version, const char *what, uint32_t lineno,
                               rs_error *err)
{
    char *save = NULL;
    const char *m = strtok_r(line, " \t", &save), *ver = strtok_r(NULL, " \t", &save);
    uint32_t v = 0;
    if (!m || strcmp(m, magic) != 0 || !ver || strtok_r(NULL, " \t", &save))
        return rs_fail(err, RS_ERR_FORMAT, "line %u: not a %s (expected '%s %u')", lineno, what, magic, version);
    if (!rs_text_parse_uint(ver, 1000000, &v) || v != version)
        return rs_fail(err, RS_ERR_FORMAT, "line %u: version '%.16s' not supported (this build reads %u)", lineno, ver,
                       version);
    return RS_OK;
}

bool rs_text_parse_uint(const char *s, uint32_t max, uint32_t *out)
{
    if (*s < '0' || *s > '9') return false;
    uint64_t v = 0;
    for (; *s; s++) {
        if (*s < '0' || *s > '9') return false;
        v = v * 10 + (uint64_t)(*s - '0');
        if (v > max) return false;
    }
    *out = (uint32_t)v;
    return true;
}


void rs_text_printf(rs_text_writer *w, const char *fmt, ...)
{
    if (w->failed) return;
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        int n = vsnprintf(w->p ? w->p + w->len : NULL, w->p ? w->cap - w->len : 0, fmt, ap);
        va_end(ap);
        if (n < 0) {
            w->failed = true;
            return;
        }
        if (w->p && (size_t)n < w->cap - w->len) {
            w->len += (size_t)n;
            return;
        }
        size_t cap = RS_MAX(w->cap * 2, w->len + (size_t)n + 256);
        char *q = realloc(w->p, cap);
        if (!q) {
            w->failed = true;
            return;
        }
        w->p = q;
        w->cap = cap;
    }
}

rs_result rs_text_writer_finish(rs_text_writer *w, const char *what, char **out, size_t *out_len, rs_error *err)
{
    if (w->failed || !w->p) {
        free(w->p);
        *w = (rs_text_writer){0};
        return rs_fail(err, RS_ERR_NOMEM, "%s: writing: out of memory", what);
    }
    *out = w->p;
    *out_len = w->len;
    *w = (rs_text_writer){0};
    return RS_OK;
}
