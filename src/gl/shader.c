// shader.c — see shader.h.
#include "gl/shader.h"

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// Line block given to sources that are not in the embedded table (tests' inline sources).
#define RS_SHADER_INLINE_FILE 999

const char *rs_shader_find(const char *name)
{
    for (int i = 0; i < rs_shader_source_count; i++)
        if (strcmp(rs_shader_sources[i].name, name) == 0) return rs_shader_sources[i].text;
    return NULL;
}

// Finds "<string>:<line>" or "<string>(<line>)" in a driver log line (Mesa, NVIDIA, ANGLE styles).
static bool parse_location(const char *s, int *line, const char **rest)
{
    for (const char *p = s; *p; p++) {
        if (!isdigit((unsigned char)*p) || (p > s && isdigit((unsigned char)p[-1]))) continue;
        char *e;
        (void)strtol(p, &e, 10);  // the source-string number: unreliable, the line encodes the file
        if (*e != ':' && *e != '(') continue;
        char *e2;
        long l = strtol(e + 1, &e2, 10);
        if (e2 == e + 1) continue;
        *line = (int)l;
        while (*e2 == ')' || *e2 == ':' || *e2 == ' ' || *e2 == '(' || isdigit((unsigned char)*e2)) e2++;
        *rest = e2;
        return true;
    }
    return false;
}

// Turns the first error of a compile log into "shaders_es/<file>:<line>: <message>".
static void describe_log(const char *log, const char *stage_name, char *out, size_t out_len)
{
    const char *start = log;
    // Prefer the first line that says "error"; fall back to the first line.
    for (const char *p = log; *p;) {
        const char *nl = strchr(p, '\n');
        size_t n = nl ? (size_t)(nl - p) : strlen(p);
        char tmp[512];
        snprintf(tmp, sizeof tmp, "%.*s", (int)RS_MIN(n, sizeof tmp - 1), p);
        for (char *c = tmp; *c; c++) *c = (char)tolower((unsigned char)*c);
        if (strstr(tmp, "error")) {
            start = p;
            break;
        }
        if (!nl) break;
        p = nl + 1;
    }
    const char *nl = strchr(start, '\n');
    int n = nl ? (int)(nl - start) : (int)strlen(start);
    char first[512];
    snprintf(first, sizeof first, "%.*s", RS_MIN(n, (int)sizeof first - 1), start);
    int line;
    const char *rest;
    if (parse_location(first, &line, &rest)) {
        const char *fname = stage_name;
        char buf[300];
        int file = line / RS_SHADER_LINE_BASE - 1;
        if (file >= 0 && file < rs_shader_source_count) {
            snprintf(buf, sizeof buf, "shaders_es/%s", rs_shader_sources[file].name);
            fname = buf;
        }
        line %= RS_SHADER_LINE_BASE;
        while (*rest == ' ') rest++;
        snprintf(out, out_len, "%s:%d: %s", fname, line, rest);
    } else {
        snprintf(out, out_len, "%s: %s", stage_name, first);
    }
}

static rs_result compile(GLenum type, const char *name, const char *text, const char *defines, GLuint *out,
                         rs_error *err)
{
    // Split after the #version line so defines land where GLSL allows them.
    const char *body = text;
    const char *nl = strchr(text, '\n');
    if (strncmp(text, "#version", 8) == 0 && nl) body = nl + 1;
    char version[64];
    snprintf(version, sizeof version, "%.*s", (int)RS_MIN((size_t)(body - text), sizeof version - 1), text);
    if (body == text) snprintf(version, sizeof version, "#version 300 es\n");
    char line_reset[48] = "";
    // Inline sources carry no #line markers: renumber so errors point at the caller's own lines.
    if (!rs_shader_find(name) || rs_shader_find(name) != text)
        snprintf(line_reset, sizeof line_reset, "#line %d\n",
                 (RS_SHADER_INLINE_FILE + 1) * RS_SHADER_LINE_BASE + (body == text ? 1 : 2));
    const char *parts[4] = {version, defines ? defines : "", line_reset, body};

    GLuint sh = glCreateShader(type);
    if (!sh) return rs_fail(err, RS_ERR_GL, "%s: glCreateShader failed (no current GL context?)", name);
    glShaderSource(sh, 4, parts, NULL);
    glCompileShader(sh);
    GLint ok = 0;
    glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[4096] = "";
        glGetShaderInfoLog(sh, sizeof log, NULL, log);
        glDeleteShader(sh);
        char shown[300];
        snprintf(shown, sizeof shown, "%s%s", rs_shader_find(name) ? "shaders_es/" : "", name);
        char msg[600];
        // Lines marked with the inline file number fall back to `shown`, the caller's name.
        describe_log(log, shown, msg, sizeof msg);
        return rs_fail(err, RS_ERR_GL, "shader compile error: %s", msg);
    }
    *out = sh;
    return RS_OK;
}

rs_result rs_shader_program_from_source(const char *vs_name, const char *vs_text, const char *fs_name,
                                        const char *fs_text, const char *defines, GLuint *out, rs_error *err)
{
    GLuint vs, fs;
    rs_result r = compile(GL_VERTEX_SHADER, vs_name, vs_text, defines, &vs, err);
    if (r) return r;
    r = compile(GL_FRAGMENT_SHADER, fs_name, fs_text, defines, &fs, err);
    if (r) {
        glDeleteShader(vs);
        return r;
    }
    GLuint prog = glCreateProgram();
    glAttachShader(prog, vs);
    glAttachShader(prog, fs);
    glLinkProgram(prog);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(prog, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[2048] = "";
        glGetProgramInfoLog(prog, sizeof log, NULL, log);
        glDeleteProgram(prog);
        char *nl = strchr(log, '\n');
        if (nl) *nl = 0;
        return rs_fail(err, RS_ERR_GL, "shader link error (%s + %s): %s", vs_name, fs_name, log);
    }
    *out = prog;
    return RS_OK;
}

rs_result rs_shader_program(const char *vs_name, const char *fs_name, const char *defines, GLuint *out,
                            rs_error *err)
{
    const char *vs = rs_shader_find(vs_name);
    const char *fs = rs_shader_find(fs_name);
    if (!vs) return rs_fail(err, RS_ERR_GL, "shader shaders_es/%s is not embedded in this build", vs_name);
    if (!fs) return rs_fail(err, RS_ERR_GL, "shader shaders_es/%s is not embedded in this build", fs_name);
    return rs_shader_program_from_source(vs_name, vs, fs_name, fs, defines, out, err);
}
