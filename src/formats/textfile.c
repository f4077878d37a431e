// textfile.c — see textfile.h.
#define _POSIX_C_SOURCE 200809L  // strtok_r
#include "formats/textfile.h"

#include <math.h>
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

bool rs_text_parse_float(const char *s, float *out)
{
    char *end;
    float v = strtof(s, &end);
    if (end == s || *end != '\0' || !isfinite(v)) return false;
    *out = v;
    return true;
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

bool rs_text_grow(void **ptr, uint32_t *cap, uint32_t need, size_t elem)
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
