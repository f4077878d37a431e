// textfile.h — the line reader and number parsing shared by rouge's versioned text formats (stroke
// files, looks).
//
// Does: walk a buffer line by line (CRLF accepted, blank and '#' lines skipped, over-long lines and NUL
// bytes refused with "line N: ..."), check a "<magic> <version>" first line, parse whole finite
// numbers, grow arrays with checked sizes.
// Does not: know any format's keywords.
//
//   rs_text_reader t = {.data = data, .len = len};
//   char buf[RS_X_MAX_LINE + 1], *line;
//   rs_result r = RS_OK;
//   while (rs_text_next_line(&t, buf, sizeof buf, &line, &r, err)) { ... t.line is the line number ... }
#ifndef RS_TEXTFILE_H
#define RS_TEXTFILE_H

#include "core/core.h"

typedef struct rs_text_reader {
    const char *data;
    size_t len, pos;
    uint32_t line;  // number of the line last returned
} rs_text_reader;

// Next line with content, NUL-terminated in buf and stripped of leading blanks. False at the end, or
// with *res set on a line longer than cap - 1 bytes or holding a NUL byte.
bool rs_text_next_line(rs_text_reader *t, char *buf, size_t cap, char **line, rs_result *res, rs_error *err);
// Checks that `line` is exactly "<magic> <version>"; `what` names the format in the error.
rs_result rs_text_check_header(char *line, const char *magic, uint32_t version, const char *what, uint32_t lineno,
                               rs_error *err);
// Whole-token parses: false on trailing garbage, non-finite values or values over max.
bool rs_text_parse_float(const char *s, float *out);
bool rs_text_parse_uint(const char *s, uint32_t max, uint32_t *out);
// Grows *ptr to hold at least `need` elements (capacity doubles, sizes checked).
bool rs_text_grow(void **ptr, uint32_t *cap, uint32_t need, size_t elem);

#endif
