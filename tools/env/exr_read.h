// exr_read.h — C interface to the OpenEXR C++ reader (exr_read.cpp), for rouge-env.
#ifndef RS_EXR_READ_H
#define RS_EXR_READ_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

// Reads R, G, B of an OpenEXR image (any compression, missing channels read as 0) into a new float array
// (*out_rgb, w * h * 3, rows top first; free()). Returns 0 on success, 2 when a side exceeds max_side
// (*out_w, *out_h say the claimed size; nothing allocated), 1 on any other failure (msg says why).
int rs_exr_read(const char *path, long long max_side, int *out_w, int *out_h, float **out_rgb, char *msg,
                size_t msg_cap);

#ifdef __cplusplus
}
#endif

#endif
