// textfile.h — the line reader and number parsing shared by rouge's versioned text formats (stroke
// files, looks).
//
// Does: walk a buffer line by line (CRLF accepted, blank and '#' lines skipped, over-long lines and NUL
// bytes refused with "line N: ..."), check a "<magic> <version>" first line, parse whole finite
// numbers (rs_parse_number underneath; arrays grow with rs_array_grow); append formatted text to a
// growing buffer.
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
// Whole-token unsigned integer: false on anything but digits, or a value over max (floats: rs_parse_float).
bool rs_text_parse_uint(const char *s, uint32_t max, uint32_t *out);

// A growing text buffer for writers: rs_text_printf appends (the buffer doubles as needed); on a failed
// allocation `failed` is set and later appends do nothing, so a writer checks once at the end.
typedef struct rs_text_writer {
    char *p;  // NUL-terminated text (malloc'd; the caller frees or hands it on)
    size_t len, cap;
    bool failed;
} rs_text_writer;
void rs_text_printf(rs_text_writer *w, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
// Hands the text over (*out, *out_len; the caller frees it) or, after a failed allocation, frees it and
// fails with "WHAT: writing: out of memory".
rs_result rs_text_writer_finish(rs_text_writer *w, const char *what, char **out, size_t *out_len, rs_error *err);

#endif
