// env_lookup.h — the bundled lighting environments by name, and where their files are found.
//
// Does: list the names a user may give (`--env`, the viewer's chips, rouge_view.env) in UI order;
// resolve a name or a .rse path to a loaded rs_env.
// Does not: render (render.h uploads an rs_env) or know the `paper` lights (callers map "paper" to
// RS_LIGHTING_LIGHTS).
//
//   rs_env *env = NULL;
//   if (rs_env_open(RS_ENV_DEFAULT, NULL, &env, &err) != RS_OK) return fail(err.msg);
#ifndef RS_ENV_LOOKUP_H
#define RS_ENV_LOOKUP_H

#include "formats/env.h"

#define RS_ENV_DEFAULT "studio"
#define RS_ENV_PAPER "paper"     // not a file: the paper's key light + ambient
#define RS_ENV_NAME_LIST "studio|daylight|office|sunset|paper"

// Bundled names, "paper" last; NULL past the end.
const char *rs_env_name(int i);
int rs_env_name_count(void);
// True for "paper".
bool rs_env_is_paper(const char *name);

// Loads environment `name` (NULL or "" = RS_ENV_DEFAULT): a bundled name, looked up as NAME.rse in `dir`
// (when given), beside the file the library runs from (dladdr: <prefix>/share/rouge/env of an installed
// package, <tree>/assets/env of a build tree) and RS_DATADIR/env, in that order (never relative to the
// working directory); or a path to a .rse file. The error names what was
// tried: "environment 'nosuch': not one of studio|daylight|office|sunset|paper and no file nosuch".
rs_result rs_env_open(const char *name, const char *dir, rs_env **out, rs_error *err);

#endif
