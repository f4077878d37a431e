// env_read.h — reads latitude-longitude HDR images for rouge-env: OpenEXR (through exr_read.cpp) and
// Radiance .hdr (stb_image). Tools-time only.
//
// Does: recognise the format by its magic bytes; check the claimed size (width = 2 x height, at most
// RS_ENVMAP_MAX_WIDTH) before allocating pixels; refuse truncated, damaged or hostile files with one line
// naming the file; drop a few negative or NaN texels and flush denormals to 0; refuse infinite radiance
// and captures with no light left (all NaN, negative, zero or denormal), naming the file and the problem.
// Does not: resample or interpret the map (env_bake.h).
//
//   rs_envmap m;
//   if (rs_envmap_read("studio.exr", &m, &err) != RS_OK) fprintf(stderr, "rouge-env: %s\n", err.msg);
#ifndef RS_ENV_READ_H
#define RS_ENV_READ_H

#include "env/env_bake.h"

// 8K x 4K: the largest common HDRI size, 400 MB as floats. Larger captures: downsample them first.
#define RS_ENVMAP_MAX_WIDTH 8192
#define RS_ENVMAP_MIN_WIDTH 16

rs_result rs_envmap_read(const char *path, rs_envmap *out, rs_error *err);
// `name` goes into messages; max_width (<= RS_ENVMAP_MAX_WIDTH) lets the fuzz harness keep inputs small.
rs_result rs_envmap_read_memory(const void *data, size_t len, const char *name, int max_width, rs_envmap *out,
                                rs_error *err);

#endif
