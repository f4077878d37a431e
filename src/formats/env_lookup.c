// env_lookup.c — bundled environment names and the file search (env_lookup.h).
#include "formats/env_lookup.h"

#include <stdio.h>
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
    const char *dirs[] = {dir, "assets/env", RS_DATADIR "/env"};
    char path[1024];
    for (size_t i = 0; i < RS_COUNT_OF(dirs); i++) {
        if (!dirs[i]) continue;
        snprintf(path, sizeof path, "%s/%s.rse", dirs[i], name);
        if (access(path, F_OK) == 0) return rs_env_load(path, out, err);
    }
    return rs_fail(err, RS_ERR_IO, "environment '%s': %s.rse is in none of %.400s%sassets/env, %s/env", name, name,
                   dir ? dir : "", dir ? ", " : "", RS_DATADIR);
}
