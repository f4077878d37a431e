// exr_read.h — C interface to the OpenEXR C++ reader (exr_read.cpp), for rouge-env and its fuzz harness.
#ifndef RS_EXR_READ_H
#define RS_EXR_READ_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

// Reads R, G, B of the OpenEXR image in data[0..len) (`name` for messages) (any compression; missing channels read as 0) into a
// new float array (*out_rgb, w * h * 3, rows top first; free()). The size is checked before anything is
// allocated for the pixels: returns 2 when the data window is not max_width x max_width / 2 or smaller
// with width = 2 x height (*out_w, *out_h say the claimed size), 1 on any other failure (msg says why:
// truncated, damaged, not EXR), 0 on success.
int rs_exr_read_memory(const void *data, size_t len, const char *name, long long max_width, int *out_w, int *out_h, float **out_rgb,
                       char *msg, size_t msg_cap);

#ifdef __cplusplus
}
#endif

#endif
