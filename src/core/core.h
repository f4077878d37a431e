// core.h — results, error messages, checked sizes and atomic file writes shared by every rouge module.
//
// Does: the rs_result enum and rs_error detail buffer that every fallible call fills; overflow-checked
// size arithmetic; whole-file reads with a size cap; atomic writes (temp file + fsync + rename).
// Does not: print anything (only the app's main prints), or own any global state.
//
//   rs_error err = {0};
//   void *data; size_t len;
//   if (rs_file_read_all("face.rsf", 1u << 30, &data, &len, &err) != RS_OK)
//       fprintf(stderr, "rouge: %s\n", err.msg);
//   free(data);
#ifndef RS_CORE_H
#define RS_CORE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef enum rs_result {
    RS_OK = 0,
    RS_ERR_IO,      // file system: missing, unreadable, unwritable, a directory
    RS_ERR_FORMAT,  // file contents are malformed
    RS_ERR_LIMIT,   // a count or size exceeds what we accept
    RS_ERR_NOMEM,   // allocation failed
    RS_ERR_GL,      // no usable GLES 3 context, shader compile/link error, incomplete FBO
    RS_ERR_ARG,     // bad option or argument from the caller/user
} rs_result;

// One-line, human-readable detail of the last failure ("face.rsf: header: bad CRC (byte 8)").
typedef struct rs_error {
    rs_result code;
    char msg[512];
} rs_error;

// Fills err (if non-NULL) and returns code, so callers can `return rs_fail(err, RS_ERR_IO, "...", ...)`.
// The message is made terminal-safe (rs_text_sanitize): messages quote file content.
rs_result rs_fail(rs_error *err, rs_result code, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
const char *rs_result_name(rs_result r);

// The sRGB transfer function (IEC 61966-2-1), c in 0..1: linear below and at the 0.04045 / 0.0031308
// thresholds. The one CPU copy (shaders_es/*.glsl use the same thresholds on the GPU).
float rs_srgb_to_linear(float c);
float rs_linear_to_srgb(float c);  // c clamped to 0..1

// Copies `src` (len bytes) into dst (cap bytes, always NUL-terminated, cut at a character boundary) so
// that a terminal shows it as text: control bytes (C0, DEL), C1 controls, bidirectional overrides and
// isolates (U+202A-202E, U+2066-2069, U+200E/F) and bytes that are not UTF-8 become \xNN or \u{XXXX}.
// File content quoted in messages and listings goes through it, so a file cannot clear or retitle the
// terminal or reorder what the user reads. Returns the length written.
size_t rs_text_sanitize(char *dst, size_t cap, const char *src, size_t len);

// Overflow-checked arithmetic: false on overflow, *out untouched.
bool rs_size_mul(size_t a, size_t b, size_t *out);
bool rs_size_add(size_t a, size_t b, size_t *out);
// malloc(a*b) with an overflow check; NULL on overflow or out of memory.
void *rs_alloc_array(size_t count, size_t elem_size);

// All of s as one finite number in [lo, hi] (strtod syntax; no blanks or characters before or after):
// the one number parser of rouge's command lines, scripts and text formats. False otherwise, *out untouched.
bool rs_parse_number(const char *s, double lo, double hi, double *out);
// Any finite float (what rouge's text formats store).
bool rs_parse_float(const char *s, float *out);
// Exactly n numbers separated by `sep` ("0.1,-0.2"), each as rs_parse_number takes it.
bool rs_parse_list(const char *s, char sep, int n, double lo, double hi, double *out);
// Grows *ptr to hold at least `need` elements of `elem` bytes: capacity doubles (from 64), sizes are
// checked, and on failure *ptr and *cap are left as they were.
bool rs_array_grow(void **ptr, uint32_t *cap, uint32_t need, size_t elem);

// Reads a whole regular file (refuses directories, devices and files larger than max_bytes).
rs_result rs_file_read_all(const char *path, size_t max_bytes, void **out_data, size_t *out_len, rs_error *err);
// Writes via "<path>.tmp.<pid>" then fsync + rename: readers see the old or the new file, never a mix.
rs_result rs_file_write_atomic(const char *path, const void *data, size_t len, rs_error *err);
// A file's identity (device + inode): one file under any of its names (hard links, ./x and x). The CLI's
// and the library's "do not overwrite the input" checks both compare these.
typedef struct rs_file_id {
    uint64_t dev, ino;
} rs_file_id;
// False when `path` is NULL or names nothing (*out untouched).
bool rs_file_id_of(const char *path, rs_file_id *out);
// True when `path` names the file `id` identifies.
bool rs_file_is(const char *path, const rs_file_id *id);
// True when `a` and `b` name the same existing file.
bool rs_same_file(const char *a, const char *b);

// Little-endian fields of binary files (every rouge format is little-endian, whatever the host).
static inline uint32_t rs_le32_get(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static inline void rs_le32_put(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v, p[1] = (uint8_t)(v >> 8), p[2] = (uint8_t)(v >> 16), p[3] = (uint8_t)(v >> 24);
}
float rs_lef32_get(const uint8_t *p);
void rs_lef32_put(uint8_t *p, float f);

// Monotonic clock in seconds, for benches and adaptive LOD (never for test assertions).
double rs_time_now(void);

// One limit per quantity, shared by the CLI, the file parsers and the renderer, so a file cannot ask for
// what the command line refuses (a stroke file's view once allowed a 16384^2 frame and a 179 degree fov).
#define RS_VIEW_MAX_SIZE_PX 8192  // frame side in pixels
#define RS_VIEW_FOV_MIN_DEG 1.0f  // vertical field of view
#define RS_VIEW_FOV_MAX_DEG 150.0f
#define RS_VIEW_PAN_MAX 2.0f      // screen shift, fractions of the view height

#define RS_COUNT_OF(a) (sizeof(a) / sizeof((a)[0]))
#define RS_MIN(a, b) ((a) < (b) ? (a) : (b))
#define RS_MAX(a, b) ((a) > (b) ? (a) : (b))
#define RS_CLAMP(x, lo, hi) RS_MIN(RS_MAX((x), (lo)), (hi))

#endif
