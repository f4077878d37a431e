// import_guard.c — what a model file must pass before assimp reads it (see import.h).
//
// Why: assimp recurses once per nesting level of a file's elements, records and nodes (a file nested
// 100000 deep overflows the stack: SIGSEGV) and allocates what an FBX array header claims before it
// inflates the data (a 496-byte file claims 2 GiB). Neither can be fixed from outside assimp, so the
// bytes are scanned first, without recursion and without allocating: nesting depth of XML elements,
// JSON containers, FBX records and glTF / COLLADA node graphs (where a node may instance another, or
// itself), and FBX array sizes against what their compressed bytes can hold. What this does not see
// (other formats, other assimp bugs) is caught by running the import in a child process with limits
// (import_assimp.c).
#define _POSIX_C_SOURCE 200809L
#include "pack/import.h"

#include <stdlib.h>
#include <string.h>

// zlib's deflate codes at most 1032 output bytes per input byte (a 258-byte match in 2 bits), so an
// array whose compressed size is n bytes holds at most 1032 n bytes (plus slack for the headers).
#define DEFLATE_MAX_RATIO 1032u

static rs_result too_deep(const char *name, const char *what, size_t at, rs_error *err)
{
    return rs_fail(err, RS_ERR_LIMIT, "%s: %s nested more than %d deep (at byte %zu); not read", name, what,
                   RS_IMPORT_MAX_DEPTH, at);
}

// ---- FBX (binary): records, their nesting and their arrays ----

static uint64_t le_get(const uint8_t *p, int bytes)
{
    uint64_t v = 0;
    for (int i = bytes - 1; i >= 0; i--) v = v << 8 | p[i];
    return v;
}

// The properties of one record: every array's claimed size against its stored bytes.
static rs_result fbx_props(const uint8_t *d, size_t at, size_t end, const char *name, rs_error *err)
{
    while (at < end) {
        uint8_t t = d[at++];
        size_t fixed = t == 'Y' ? 2 : t == 'C' ? 1 : (t == 'I' || t == 'F') ? 4 : (t == 'D' || t == 'L') ? 8 : 0;
        if (fixed) {
            at += fixed;
            continue;
        }
        if (t == 'S' || t == 'R') {
            if (end - at < 4) return RS_OK;
            at += 4 + le_get(d + at, 4);
            continue;
        }
        size_t stride = t == 'f' || t == 'i' ? 4 : t == 'd' || t == 'l' ? 8 : t == 'b' ? 1 : 0;
        // An unknown type or a cut header: assimp's own checks refuse the file.
        if (!stride || end - at < 12) return RS_OK;
        uint64_t count = le_get(d + at, 4), encoding = le_get(d + at + 4, 4), stored = le_get(d + at + 8, 4);
        uint64_t claimed = count * stride;
        uint64_t can = encoding == 0 ? stored : stored * DEFLATE_MAX_RATIO + 64;
        if (claimed > can || claimed > RS_IMPORT_MAX_FILE)
            return rs_fail(err, RS_ERR_LIMIT,
                           "%s: an FBX array at byte %zu claims %llu bytes from %llu stored bytes (a decompression bomb); not read",
                           name, at - 1, (unsigned long long)claimed, (unsigned long long)stored);
        at += 12 + stored;
    }
    return RS_OK;
}

static rs_result guard_fbx_binary(const uint8_t *d, size_t n, const char *name, rs_error *err)
{
    if (n < 27) return RS_OK;
    // Version 7500 and later use 64-bit offsets (a 25-byte record header).
    int w = le_get(d + 23, 4) >= 7500 ? 8 : 4;
    size_t head = 3 * (size_t)w + 1;
    size_t ends[RS_IMPORT_MAX_DEPTH + 1];
    int depth = 0;
    size_t at = 27;
    while (at + head <= n) {
        while (depth > 0 && at >= ends[depth - 1]) depth--;
        uint64_t end = le_get(d + at, w), props_len = le_get(d + at + 2 * w, w);
        size_t name_len = d[at + 3 * w];
        if (end == 0) {  // a null record closes a list
            at += head;
            continue;
        }
        if (end <= at || end > n || head + name_len > end - at || props_len > end - at - head - name_len) return RS_OK;
        size_t props = at + head + name_len;
        rs_result r = fbx_props(d, props, props + props_len, name, err);
        if (r != RS_OK) return r;
        if (depth == RS_IMPORT_MAX_DEPTH) return too_deep(name, "FBX records", at, err);
        ends[depth++] = end;
        at = props + props_len;  // the first nested record, or the next one
    }
    return RS_OK;
}

// ---- text: JSON containers, XML elements, ASCII FBX braces ----

static rs_result guard_json(const uint8_t *d, size_t n, const char *name, rs_error *err)
{
    int depth = 0;
    bool in_str = false;
    for (size_t i = 0; i < n; i++) {
        uint8_t c = d[i];
        if (in_str) {
            if (c == '\\') i++;
            else if (c == '"') in_str = false;
        } else if (c == '"') {
            in_str = true;
        } else if (c == '{' || c == '[') {
            if (++depth > RS_IMPORT_MAX_DEPTH) return too_deep(name, "JSON objects and arrays", i, err);
        } else if (c == '}' || c == ']') {
            depth -= depth > 0;
        }
    }
    return RS_OK;
}

static rs_result guard_braces(const uint8_t *d, size_t n, const char *name, rs_error *err)
{
    int depth = 0;
    bool in_str = false;
    for (size_t i = 0; i < n; i++) {
        if (d[i] == '"') in_str = !in_str;
        else if (d[i] == '\n') in_str = false;
        else if (!in_str && d[i] == '{' && ++depth > RS_IMPORT_MAX_DEPTH) return too_deep(name, "FBX scopes", i, err);
        else if (!in_str && d[i] == '}') depth -= depth > 0;
    }
    return RS_OK;
}

static const uint8_t *find(const uint8_t *d, size_t from, size_t n, const char *s)
{
    size_t k = strlen(s);
    for (size_t i = from; i + k <= n; i++)
        if (d[i] == (uint8_t)s[0] && !memcmp(d + i, s, k)) return d + i;
    return NULL;
}

// ---- node graphs: COLLADA <node> / <instance_node>, glTF "children" ----
//
// A node is drawn once per path to it from a root, so the importer's tree is the graph unrolled: a cycle
// never ends, a chain is as deep as its longest path, and a node instanced twice by each of 30 levels
// becomes 2^30 nodes. Checked on the graph: no cycle, depth and unrolled size within the limits.

typedef struct graph {
    uint32_t count;         // nodes
    uint32_t edge_count, edge_cap;
    uint32_t (*edges)[2];   // parent, child
} graph;

static bool graph_edge(graph *g, uint32_t from, uint32_t to)
{
    if (g->edge_count == g->edge_cap) {
        uint32_t cap = g->edge_cap ? g->edge_cap * 2 : 256;
        void *e = realloc(g->edges, (size_t)cap * sizeof *g->edges);
        if (!e) return false;
        g->edges = e;
        g->edge_cap = cap;
    }
    g->edges[g->edge_count][0] = from;
    g->edges[g->edge_count][1] = to;
    g->edge_count++;
    return true;
}

static int cmp_edge(const void *a, const void *b)
{
    const uint32_t *x = a, *y = b;
    return x[0] != y[0] ? (x[0] > y[0]) - (x[0] < y[0]) : (x[1] > y[1]) - (x[1] < y[1]);
}

// Depth-first without recursion, children before parents: every node's longest path down and how many
// nodes it unrolls to (saturating at the limit).
static rs_result graph_check(graph *g, const char *name, const char *what, rs_error *err)
{
    if (!g->count) return RS_OK;
    if (g->edge_count) qsort(g->edges, g->edge_count, sizeof *g->edges, cmp_edge);  // no edges: edges may be NULL
    uint32_t *first = calloc((size_t)g->count + 1, sizeof *first);
    uint8_t *state = calloc(g->count, 1);  // 0 new, 1 on the path, 2 done
    uint32_t *depth = calloc(g->count, sizeof *depth);
    uint64_t *size = calloc(g->count, sizeof *size);
    uint32_t *stack = malloc((size_t)g->count * sizeof *stack), *next = malloc((size_t)g->count * sizeof *next);
    rs_result r = RS_OK;
    if (!first || !state || !depth || !size || !stack || !next) {
        r = rs_fail(err, RS_ERR_NOMEM, "%s: out of memory checking %u nodes", name, g->count);
        goto done;
    }
    for (uint32_t e = 0; e < g->edge_count; e++) first[g->edges[e][0] + 1]++;
    for (uint32_t v = 0; v < g->count; v++) first[v + 1] += first[v];
    for (uint32_t root = 0; root < g->count && r == RS_OK; root++) {
        if (state[root]) continue;
        uint32_t top = 0;
        stack[top] = root, next[top] = first[root], state[root] = 1, top++;
        while (top && r == RS_OK) {
            uint32_t v = stack[top - 1];
            if (next[top - 1] < first[v + 1]) {
                uint32_t c = g->edges[next[top - 1]++][1];
                if (state[c] == 1) {
                    r = rs_fail(err, RS_ERR_FORMAT, "%s: %s %u contains itself (a cycle of instances); not read", name, what, c);
                } else if (state[c] == 0) {
                    stack[top] = c, next[top] = first[c], state[c] = 1, top++;
                }
                continue;
            }
            // All children done: this node's depth and unrolled size.
            uint32_t d = 0;
            uint64_t s = 1;
            for (uint32_t e = first[v]; e < first[v + 1]; e++) {
                uint32_t c = g->edges[e][1];
                d = RS_MAX(d, depth[c] + 1);
                s = RS_MIN(s + size[c], (uint64_t)RS_IMPORT_MAX_NODES + 1);
            }
            depth[v] = d, size[v] = s, state[v] = 2;
            if (d > RS_IMPORT_MAX_DEPTH)
                r = rs_fail(err, RS_ERR_LIMIT, "%s: %s %u heads a hierarchy more than %d deep; not read", name, what, v,
                            RS_IMPORT_MAX_DEPTH);
            else if (s > RS_IMPORT_MAX_NODES)
                r = rs_fail(err, RS_ERR_LIMIT, "%s: %s %u unrolls to more than %u nodes (nodes instanced many times over); not read",
                            name, what, v, RS_IMPORT_MAX_NODES);
            top--;
        }
    }
done:
    free(first), free(state), free(depth), free(size), free(stack), free(next);
    return r;
}

// An XML tag at d[i] == '<': where it ends (after '>'), whether it closes or is self-closing.
static size_t xml_tag_end(const uint8_t *d, size_t i, size_t n)
{
    uint8_t q = 0;
    for (size_t k = i + 1; k < n; k++) {
        if (q) q = d[k] == q ? 0 : q;
        else if (d[k] == '"' || d[k] == '\'') q = d[k];
        else if (d[k] == '>') return k + 1;
    }
    return n;
}

// The value of attribute `attr` in the tag d[i..e), or NULL; *len its length.
static const uint8_t *xml_attr(const uint8_t *d, size_t i, size_t e, const char *attr, size_t *len)
{
    size_t k = strlen(attr);
    for (size_t p = i; p + k + 2 < e; p++) {
        if ((d[p] != ' ' && d[p] != '\t' && d[p] != '\n' && d[p] != '\r') || memcmp(d + p + 1, attr, k) || d[p + k + 1] != '=')
            continue;
        uint8_t q = d[p + k + 2];
        if (q != '"' && q != '\'') return NULL;
        const uint8_t *v = d + p + k + 3, *c = memchr(v, q, e - (size_t)(v - d));
        if (!c) return NULL;
        *len = (size_t)(c - v);
        return v;
    }
    return NULL;
}

typedef struct xml_id {
    const uint8_t *id;
    size_t len;
    uint32_t node;
} xml_id;

static int cmp_id(const void *a, const void *b)
{
    const xml_id *x = a, *y = b;
    size_t k = RS_MIN(x->len, y->len);
    int c = memcmp(x->id, y->id, k);
    return c ? c : (x->len > y->len) - (x->len < y->len);
}

// Element nesting, and for COLLADA the node graph: <node> inside <node>, and <instance_node url="#id">.
static rs_result guard_xml(const uint8_t *d, size_t n, bool collada, const char *name, rs_error *err)
{
    int depth = 0;
    uint32_t open[RS_IMPORT_MAX_DEPTH + 1];  // the enclosing <node>s
    int open_depth[RS_IMPORT_MAX_DEPTH + 1];
    int open_count = 0;
    graph g = {0};
    xml_id *ids = NULL, *refs = NULL;  // node ids; instance_node targets (node = the instancing node)
    size_t id_count = 0, id_cap = 0, ref_count = 0, ref_cap = 0;
    rs_result r = RS_OK;
    for (size_t i = 0; i < n && r == RS_OK;) {
        const uint8_t *lt = memchr(d + i, '<', n - i);
        if (!lt) break;
        i = (size_t)(lt - d);
        const char *skip_to = n - i >= 4 && !memcmp(lt, "<!--", 4) ? "-->"
                              : n - i >= 9 && !memcmp(lt, "<![CDATA[", 9) ? "]]>"
                              : n - i >= 2 && lt[1] == '?' ? "?>"
                              : NULL;
        if (skip_to) {
            const uint8_t *e = find(d, i + 2, n, skip_to);
            i = e ? (size_t)(e - d) + strlen(skip_to) : n;
            continue;
        }
        size_t e = xml_tag_end(d, i, n);
        bool closing = i + 1 < n && d[i + 1] == '/', self = e >= 2 && d[e - 2] == '/', decl = i + 1 < n && d[i + 1] == '!';
        if (closing) {
            depth -= depth > 0;
            if (open_count && open_depth[open_count - 1] == depth) open_count--;
        } else if (!decl) {
            if (!self && ++depth > RS_IMPORT_MAX_DEPTH) {
                r = too_deep(name, "XML elements", i, err);
                break;
            }
            bool is_node = collada && e - i > 6 && !memcmp(d + i + 1, "node", 4) && strchr(" \t\r\n/>", d[i + 5]);
            bool is_inst = collada && e - i > 15 && !memcmp(d + i + 1, "instance_node", 13) && strchr(" \t\r\n/>", d[i + 14]);
            if (is_node) {
                uint32_t v = g.count++;
                if (g.count > RS_IMPORT_MAX_NODES) {
                    r = rs_fail(err, RS_ERR_LIMIT, "%s: more than %u nodes; not read", name, RS_IMPORT_MAX_NODES);
                    break;
                }
                if (open_count && !graph_edge(&g, open[open_count - 1], v)) r = rs_fail(err, RS_ERR_NOMEM, "out of memory");
                size_t len;
                const uint8_t *id = xml_attr(d, i, e, "id", &len);
                if (id && r == RS_OK) {
                    if (id_count == id_cap) {
                        id_cap = id_cap ? id_cap * 2 : 64;
                        void *p = realloc(ids, id_cap * sizeof *ids);
                        if (!p) r = rs_fail(err, RS_ERR_NOMEM, "out of memory");
                        else ids = p;
                    }
                    if (r == RS_OK) ids[id_count++] = (xml_id){id, len, v};
                }
                if (!self) open[open_count] = v, open_depth[open_count] = depth - 1, open_count++;
            } else if (is_inst && open_count) {
                size_t len;
                const uint8_t *url = xml_attr(d, i, e, "url", &len);
                if (url && len > 1 && url[0] == '#') {
                    if (ref_count == ref_cap) {
                        ref_cap = ref_cap ? ref_cap * 2 : 64;
                        void *p = realloc(refs, ref_cap * sizeof *refs);
                        if (!p) r = rs_fail(err, RS_ERR_NOMEM, "out of memory");
                        else refs = p;
                    }
                    if (r == RS_OK) refs[ref_count++] = (xml_id){url + 1, len - 1, open[open_count - 1]};
                }
            }
        }
        i = e;
    }
    if (r == RS_OK && collada && g.count) {
        // With no node ids, ids is NULL, which qsort and bsearch must not be given (and no reference can hit).
        if (id_count) qsort(ids, id_count, sizeof *ids, cmp_id);
        for (size_t k = 0; k < ref_count && id_count && r == RS_OK; k++) {
            xml_id *hit = bsearch(&refs[k], ids, id_count, sizeof *ids, cmp_id);
            if (hit && !graph_edge(&g, refs[k].node, hit->node)) r = rs_fail(err, RS_ERR_NOMEM, "out of memory");
        }
        if (r == RS_OK) r = graph_check(&g, name, "COLLADA node", err);
    }
    free(ids), free(refs), free(g.edges);
    return r;
}

// glTF: the "nodes" array of the top-level object, each node's "children" indices. A small scanner for
// just that: strings skipped, depth tracked, numbers read where "children" is open. Also every
// "mimeType" value: assimp 5.2 takes an embedded image's file type from after its '/', and one without
// a '/' made it read from address 1 (a crash, found by make fuzz).
static rs_result guard_gltf_nodes(const uint8_t *d, size_t n, const char *name, rs_error *err)
{
    graph g = {0};
    rs_result r = RS_OK;
    int depth = 0, nodes_depth = -1, children_depth = -1;
    const uint8_t *key = NULL;  // the last string at object level (a key when a ':' follows)
    size_t key_len = 0;
    bool mime = false;  // a ':' after the key "mimeType": the next string is its value
    for (size_t i = 0; i < n && r == RS_OK; i++) {
        uint8_t c = d[i];
        if (c == '"') {
            size_t s = ++i;
            while (i < n && d[i] != '"') i += d[i] == '\\' ? 2 : 1;
            key = d + s, key_len = RS_MIN(i, n) - s;
            if (mime && !memchr(key, '/', key_len))
                r = rs_fail(err, RS_ERR_FORMAT, "%s: a glTF image's mimeType is not of the form type/subtype; not read",
                            name);
            mime = false;
            continue;
        }
        if (c == ':') {
            mime = key && key_len == 8 && !memcmp(key, "mimeType", 8);
            continue;
        }
        if (c != ' ' && c != '\t' && c != '\r' && c != '\n') mime = false;
        if (c == '{' || c == '[') {
            depth++;
            bool named = key && key_len > 0;
            if (c == '[' && depth == 2 && named && key_len == 5 && !memcmp(key, "nodes", 5)) nodes_depth = depth;
            else if (c == '{' && nodes_depth > 0 && depth == nodes_depth + 1) g.count++;  // node g.count - 1
            else if (c == '[' && nodes_depth > 0 && depth == nodes_depth + 2 && named && key_len == 8 &&
                     !memcmp(key, "children", 8))
                children_depth = depth;
            key = NULL;
            if (g.count > RS_IMPORT_MAX_NODES) r = rs_fail(err, RS_ERR_LIMIT, "%s: more than %u nodes; not read", name, RS_IMPORT_MAX_NODES);
        } else if (c == '}' || c == ']') {
            if (depth == children_depth) children_depth = -1;
            if (depth == nodes_depth) nodes_depth = -1;
            depth--;
        } else if (c >= '0' && c <= '9' && depth == children_depth && g.count) {
            uint64_t v = 0;
            for (; i < n && d[i] >= '0' && d[i] <= '9'; i++) v = RS_MIN(v * 10 + (uint64_t)(d[i] - '0'), (uint64_t)UINT32_MAX);
            i--;
            if (!graph_edge(&g, g.count - 1, (uint32_t)v)) r = rs_fail(err, RS_ERR_NOMEM, "out of memory");
        } else if (c == ',') {
            key = NULL;
        }
    }
    // Indices past the array are assimp's to refuse; drop them here.
    uint32_t k = 0;
    for (uint32_t e = 0; e < g.edge_count; e++)
        if (g.edges[e][1] < g.count) g.edges[k][0] = g.edges[e][0], g.edges[k][1] = g.edges[e][1], k++;
    g.edge_count = k;
    if (r == RS_OK) r = graph_check(&g, name, "glTF node", err);
    free(g.edges);
    return r;
}

rs_result rs_import_guard(const void *data, size_t n, rs_import_format format, const char *name, rs_error *err)
{
    const uint8_t *d = data;
    if (n >= 18 && !memcmp(d, "Kaydara FBX Binary", 18)) return guard_fbx_binary(d, n, name, err);
    if (n >= 20 && !memcmp(d, "glTF", 4)) {
        // GLB: the JSON chunk (length, "JSON") after the 12-byte header.
        uint64_t len = le_get(d + 12, 4);
        if (memcmp(d + 16, "JSON", 4) || len > n - 20) return RS_OK;
        rs_result r = guard_json(d + 20, len, name, err);
        return r == RS_OK ? guard_gltf_nodes(d + 20, len, name, err) : r;
    }
    size_t i = 0;
    while (i < n && (d[i] == ' ' || d[i] == '\t' || d[i] == '\r' || d[i] == '\n')) i++;
    if (n - i >= 3 && d[i] == 0xef && d[i + 1] == 0xbb && d[i + 2] == 0xbf) i += 3;
    if (format == RS_IMPORT_GLTF || (i < n && (d[i] == '{' || d[i] == '[') && format == RS_IMPORT_OTHER)) {
        rs_result r = guard_json(d, n, name, err);
        return r == RS_OK ? guard_gltf_nodes(d, n, name, err) : r;
    }
    if (format == RS_IMPORT_FBX) return guard_braces(d, n, name, err);
    if (i < n && d[i] == '<')
        return guard_xml(d, n, format == RS_IMPORT_DAE || find(d, 0, RS_MIN(n, (size_t)4096), "<COLLADA"), name, err);
    return RS_OK;
}
