// env_lookup.c — bundled environment names and the file search (env_lookup.h).
#define _GNU_SOURCE  // dladdr (glibc, musl, bionic, macOS; emscripten's answers "unknown")
#include "formats/env_lookup.h"

#include <dlfcn.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#ifndef RS_DATADIR
#define RS_DATADIR "/usr/local/share/rouge"  // the Makefile passes $(PREFIX)/share/rouge
#endif

static const char *const names[] = {"studio", "daylight", "office", "sunset", RS_ENV_PAPER};

const char *rs_env_name(int i) { return i >= 0 && i < (int)RS_COUNT_OF(names) ? names[i] : NULL; }
int rs_env_name_count(void) { return (int)RS_COUNT_OF(names); }
bool rs_env_is_paper(const char *name) { return name && strcmp(name, RS_ENV_PAPER) == 0; }

static bool bundled(const char *name)
{
    for (size_t i = 0; i + 1 < RS_COUNT_OF(names); i++)
        if (strcmp(name, names[i]) == 0) return true;
    return false;
}

// The environments found from where this code runs, not from the host's working directory: the file
// holding it (librouge.so, or the program a static librouge.a went into) sits in <prefix>/lib,
// <prefix>/lib/<triplet> or <prefix>/bin of an installed package (its data: <prefix>/share/rouge/env,
// whatever PREFIX it was compiled with), or in build/ or build/<dir>/ of a source tree (<tree>/assets/env).
static bool env_beside_self(char *out, size_t n)
{
    Dl_info info;
    char self[PATH_MAX];
    if (!dladdr((const void *)&env_beside_self, &info) || !info.dli_fname) return false;
    // The main program's name may be argv[0], relative to a working directory the host has since left:
    // then Linux's link to the program.
    if (!realpath(info.dli_fname, self) && !realpath("/proc/self/exe", self)) return false;
    for (int up = 0; up < 2; up++) {
        char *slash = strrchr(self, '/');
        if (!slash || slash == self) return false;
        *slash = 0;  // the file's folder, then that folder's
        int len = (int)(strrchr(self, '/') - self);
        const char *data[] = {"share/rouge/env", "assets/env"};
        for (size_t i = 0; i < RS_COUNT_OF(data); i++) {
            snprintf(out, n, "%.*s/%s", len, self, data[i]);
            if (access(out, F_OK) == 0) return true;
        }
    }
    return false;
}

rs_result rs_env_open(const char *name, const char *dir, rs_env **out, rs_error *err)
{
    *out = NULL;
    if (!name || !name[0]) name = RS_ENV_DEFAULT;
    if (!bundled(name)) {
        size_t n = strlen(name);
        if (n > 4 && strcmp(name + n - 4, ".rse") == 0) return rs_env_load(name, out, err);
        return rs_fail(err, RS_ERR_ARG, "environment '%.64s': not one of %s, nor a .rse file", name,
                       RS_ENV_NAME_LIST);
    }
    // The caller's folder; the installed package's or the build tree's; the PREFIX it was built for.
    char beside[PATH_MAX];
    const char *dirs[] = {dir, env_beside_self(beside, sizeof beside) ? beside : NULL, RS_DATADIR "/env"};
    char path[PATH_MAX + 64], tried[600] = "";
    for (size_t i = 0; i < RS_COUNT_OF(dirs); i++) {
        if (!dirs[i]) continue;
        snprintf(path, sizeof path, "%s/%s.rse", dirs[i], name);
        if (access(path, F_OK) == 0) return rs_env_load(path, out, err);
        size_t t = strlen(tried);
        snprintf(tried + t, sizeof tried - t, "%s%s", t ? ", " : "", dirs[i]);
    }
    return rs_fail(err, RS_ERR_IO, "environment '%s': %s.rse is in none of %s", name, name, tried);
}
