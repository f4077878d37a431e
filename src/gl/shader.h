// shader.h — GLSL ES 3.00 programs from shaders_es/, embedded in the binary at build time.
//
// Does: look up embedded sources by file name (tools/embed_shaders.c resolves `#include "x.glsl"`),
// insert per-program #defines after the #version line, compile and link, and turn the driver's log
// into one line naming the shader file and line ("shaders_es/splat.frag.glsl:42: 'foo' undeclared").
// Does not: read shader files at run time (an installed binary needs no shader folder), or cache.
//
//   GLuint prog;
//   if (rs_shader_program("splat.vert.glsl", "splat.frag.glsl", "#define RS_PASS_DEPTH 1\n", &prog, &err))
//       return err.code;
//   ...
//   glDeleteProgram(prog);
#ifndef RS_GL_SHADER_H
#define RS_GL_SHADER_H

#include "core/core.h"

#include <GLES3/gl3.h>

typedef struct rs_shader_source {
    const char *name;  // file name in shaders_es/, e.g. "splat.vert.glsl"
    const char *text;  // with includes expanded and #line markers
} rs_shader_source;

// Embedded sources number their lines (file_index + 1) * RS_SHADER_LINE_BASE + line, so a driver's
// "0:LINE" names the file too.
#define RS_SHADER_LINE_BASE 10000

// Generated table (build/gen/shaders.c).
extern const rs_shader_source rs_shader_sources[];
extern const int rs_shader_source_count;

// NULL when no embedded shader has that name.
const char *rs_shader_find(const char *name);

// Compiles and links embedded shaders; `defines` (may be NULL) go right after #version.
rs_result rs_shader_program(const char *vs_name, const char *fs_name, const char *defines, GLuint *out,
                            rs_error *err);
// Same from explicit sources (names are used in error messages); for tests of the error path.
rs_result rs_shader_program_from_source(const char *vs_name, const char *vs_text, const char *fs_name,
                                        const char *fs_text, const char *defines, GLuint *out, rs_error *err);

#endif
