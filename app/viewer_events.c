// viewer_events.c — the viewer's event queue and its event script (format in viewer_internal.h). A
// script is parsed whole before the window opens, so a typo fails fast with file:line; the player then
// feeds the same queue the mouse and keyboard feed, so a script exercises exactly the code a person does.
#define _POSIX_C_SOURCE 200809L
#include "viewer_internal.h"

#include "formats/textfile.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <ctype.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

void vw_queue_push(vw_queue *q, const vw_event *ev)
{
    if (q->count == VW_QUEUE_CAP) {
        q->dropped++;
        return;
    }
    q->ev[(q->head + q->count) % VW_QUEUE_CAP] = *ev;
    q->count++;
}

bool vw_queue_peek(const vw_queue *q, vw_event *ev)
{
    if (!q->count) return false;
    *ev = q->ev[q->head];
    return true;
}

bool vw_queue_pop(vw_queue *q, vw_event *ev)
{
    if (!vw_queue_peek(q, ev)) return false;
    q->head = (q->head + 1) % VW_QUEUE_CAP;
    q->count--;
    return true;
}

// --- keys ----------------------------------------------------------------------------------------------

static const struct {
    const char *name;
    int key;
} named_keys[] = {
    {"esc", GLFW_KEY_ESCAPE},     {"escape", GLFW_KEY_ESCAPE}, {"tab", GLFW_KEY_TAB},
    {"space", GLFW_KEY_SPACE},    {"enter", GLFW_KEY_ENTER},   {"return", GLFW_KEY_ENTER},
    {"left", GLFW_KEY_LEFT},      {"right", GLFW_KEY_RIGHT},   {"up", GLFW_KEY_UP},
    {"down", GLFW_KEY_DOWN},      {"delete", GLFW_KEY_DELETE}, {"backspace", GLFW_KEY_BACKSPACE},
    {"home", GLFW_KEY_HOME},      {"pageup", GLFW_KEY_PAGE_UP}, {"pagedown", GLFW_KEY_PAGE_DOWN},
};

bool vw_key_from_name(const char *name, int *key, int *mods)
{
    int m = 0;
    for (;;) {
        if (!strncmp(name, "ctrl+", 5)) m |= GLFW_MOD_CONTROL, name += 5;
        else if (!strncmp(name, "shift+", 6)) m |= GLFW_MOD_SHIFT, name += 6;
        else if (!strncmp(name, "alt+", 4)) m |= GLFW_MOD_ALT, name += 4;
        else break;
    }
    if (!name[0]) return false;
    if (!name[1]) {
        // One character: GLFW names printable keys by their unshifted US-layout character.
        unsigned char c = (unsigned char)name[0];
        static const char shifted[] = "?+{}_:\"<>~!@#$%^&*()";
        static const char base[] = "/=[]-;',.`1234567890";
        const char *p = strchr(shifted, c);
        if (p && c) {
            c = (unsigned char)base[p - shifted];
            m |= GLFW_MOD_SHIFT;
        }
        if (isalpha(c)) {
            if (isupper(c)) m |= GLFW_MOD_SHIFT;
            *key = toupper(c);
        } else if (isdigit(c) || strchr("/=[]-;',.`\\", c)) {
            *key = c;
        } else {
            return false;
        }
        *mods = m;
        return true;
    }
    if ((name[0] == 'f' || name[0] == 'F') && isdigit((unsigned char)name[1])) {
        int n = atoi(name + 1);
        if (n < 1 || n > 12) return false;
        *key = GLFW_KEY_F1 + n - 1, *mods = m;
        return true;
    }
    for (size_t i = 0; i < RS_COUNT_OF(named_keys); i++)
        if (!strcmp(name, named_keys[i].name)) {
            *key = named_keys[i].key, *mods = m;
            return true;
        }
    return false;
}

// --- parsing ---------------------------------------------------------------------------------------

typedef struct parser {
    vw_script *s;
    const char *file;
    int line;
    int cap;
    rs_error *err;
} parser;

static rs_result add(parser *p, const vw_cmd *c)
{
    if (p->s->count >= VW_SCRIPT_MAX_CMDS)
        return rs_fail(p->err, RS_ERR_LIMIT, "%s:%d: more than %d events", p->file, p->line, VW_SCRIPT_MAX_CMDS);
    if (p->s->count == p->cap) {
        int n = p->cap ? p->cap * 2 : 256;
        vw_cmd *q = rs_alloc_array((size_t)n, sizeof *q);
        if (!q) return rs_fail(p->err, RS_ERR_NOMEM, "%s: out of memory", p->file);
        if (p->s->count) memcpy(q, p->s->cmd, (size_t)p->s->count * sizeof *q);
        free(p->s->cmd);
        p->s->cmd = q, p->cap = n;
    }
    vw_cmd *d = &p->s->cmd[p->s->count++];
    *d = *c;
    d->line = p->line;
    return RS_OK;
}

static rs_result add_event(parser *p, vw_event ev, bool advance)
{
    return add(p, &(vw_cmd){.type = VW_CMD_EVENT, .ev = ev, .advance = advance});
}

static bool button_name(const char *tok, int *b)
{
    if (!tok || !strcmp(tok, "left")) return *b = 0, true;
    if (!strcmp(tok, "right")) return *b = 1, true;
    if (!strcmp(tok, "middle")) return *b = 2, true;
    return false;
}

#define COORD_MAX 100000.0

static rs_result parse_line(parser *p, char **tok, int n)
{
    const char *c = tok[0];
    double a[4] = {0};
    rs_error *err = p->err;
#define BAD(what) rs_fail(err, RS_ERR_FORMAT, "%s:%d: %s: %s", p->file, p->line, c, what)
    if (!strcmp(c, "move") || !strcmp(c, "click")) {
        if (n != 3 || !rs_parse_number(tok[1], -COORD_MAX, COORD_MAX, &a[0]) || !rs_parse_number(tok[2], -COORD_MAX, COORD_MAX, &a[1]))
            return BAD("expected X Y");
        vw_event ev = {.type = VW_MOVE, .x = (float)a[0], .y = (float)a[1]};
        rs_result r = add_event(p, ev, true);
        if (r || !strcmp(c, "move")) return r;
        ev.type = VW_BUTTON, ev.button = 0, ev.down = true;
        if ((r = add_event(p, ev, false))) return r;
        ev.down = false;
        return add_event(p, ev, true);
    }
    if (!strcmp(c, "down") || !strcmp(c, "up")) {
        int b;
        if (n > 2 || !button_name(n > 1 ? tok[1] : NULL, &b)) return BAD("expected left, right or middle");
        // Position: the player fills in the pointer's current position.
        return add_event(p, (vw_event){.type = VW_BUTTON, .button = b, .down = c[0] == 'd', .x = NAN}, false);
    }
    if (!strcmp(c, "drag")) {
        if (n < 5 || n > 7) return BAD("expected X0 Y0 X1 Y1 [STEPS] [BUTTON]");
        for (int i = 0; i < 4; i++)
            if (!rs_parse_number(tok[1 + i], -COORD_MAX, COORD_MAX, &a[i])) return BAD("coordinates must be numbers");
        double steps = 20;
        int b = 0, k = 5;
        if (n > k && isdigit((unsigned char)tok[k][0])) {
            if (!rs_parse_number(tok[k], 1, 10000, &steps) || steps != floor(steps)) return BAD("STEPS must be 1..10000");
            k++;
        }
        if (n > k && !button_name(tok[k], &b)) return BAD("button must be left, right or middle");
        if (n > k + 1) return BAD("too many values");
        vw_event ev = {.type = VW_MOVE, .x = (float)a[0], .y = (float)a[1]};
        rs_result r = add_event(p, ev, true);
        if (!r) r = add_event(p, (vw_event){.type = VW_BUTTON, .button = b, .down = true, .x = ev.x, .y = ev.y}, false);
        for (int i = 1; !r && i <= (int)steps; i++) {
            double t = (double)i / steps;
            ev.x = (float)(a[0] + (a[2] - a[0]) * t), ev.y = (float)(a[1] + (a[3] - a[1]) * t);
            r = add_event(p, ev, true);
        }
        if (!r) r = add_event(p, (vw_event){.type = VW_BUTTON, .button = b, .down = false, .x = ev.x, .y = ev.y}, true);
        return r;
    }
    if (!strcmp(c, "scroll")) {
        if (n != 2 || !rs_parse_number(tok[1], -100, 100, &a[0])) return BAD("expected DY (-100..100)");
        return add_event(p, (vw_event){.type = VW_SCROLL, .dy = (float)a[0]}, true);
    }
    if (!strcmp(c, "key") || !strcmp(c, "keydown") || !strcmp(c, "keyup")) {
        int key, mods;
        if (n != 2) return BAD("expected one key name");
        if (!vw_key_from_name(tok[1], &key, &mods))
            return rs_fail(err, RS_ERR_FORMAT, "%s:%d: %s: unknown key '%s'", p->file, p->line, c, tok[1]);
        vw_event ev = {.type = VW_KEY, .key = key, .mods = mods, .down = true};
        rs_result r = c[3] == 'u' ? RS_OK : add_event(p, ev, true);
        ev.down = false;
        if (!r && c[3] != 'd') r = add_event(p, ev, c[3] == 'u');
        return r;
    }
    if (!strcmp(c, "type")) {
        // The rest of the line (words joined by single spaces), one character event each.
        if (n < 2) return BAD("expected TEXT");
        rs_result r = RS_OK;
        for (int k = 1; k < n && !r; k++) {
            if (k > 1) r = add_event(p, (vw_event){.type = VW_CHAR, .key = ' '}, false);
            for (const char *q = tok[k]; *q && !r; q++)
                r = add_event(p, (vw_event){.type = VW_CHAR, .key = (unsigned char)*q}, false);
        }
        return r;
    }
    if (!strcmp(c, "touch")) {
        if (n != 5 || !rs_parse_number(tok[1], 1, 9, &a[0]) || a[0] != floor(a[0])) return BAD("expected ID (1..9) down|move|up X Y");
        rouge_pointer_type t;
        if (!strcmp(tok[2], "down")) t = ROUGE_POINTER_DOWN;
        else if (!strcmp(tok[2], "move")) t = ROUGE_POINTER_MOVE;
        else if (!strcmp(tok[2], "up")) t = ROUGE_POINTER_UP;
        else return BAD("expected down, move or up");
        if (!rs_parse_number(tok[3], -COORD_MAX, COORD_MAX, &a[1]) || !rs_parse_number(tok[4], -COORD_MAX, COORD_MAX, &a[2]))
            return BAD("coordinates must be numbers");
        return add_event(p, (vw_event){.type = VW_TOUCH, .id = (int)a[0], .touch = t, .x = (float)a[1], .y = (float)a[2]},
                         true);
    }
    if (!strcmp(c, "screenshot") && n == 6) {
        vw_cmd cmd = {.type = VW_CMD_SCREENSHOT};
        for (int i = 0; i < 4; i++)
            if (!rs_parse_number(tok[2 + i], i < 2 ? 0 : 1, COORD_MAX, &a[i]) || a[i] != floor(a[i]))
                return BAD("region X Y W H must be whole numbers, W and H at least 1");
        if (strlen(tok[1]) >= sizeof cmd.path) return BAD("file name too long");
        snprintf(cmd.path, sizeof cmd.path, "%s", tok[1]);
        for (int i = 0; i < 4; i++) cmd.rect[i] = (float)a[i];
        return add(p, &cmd);
    }
    if (!strcmp(c, "state")) {
        if (n != 2) return BAD("expected one file name (no spaces)");
        vw_cmd cmd = {.type = VW_CMD_STATE};
        if (strlen(tok[1]) >= sizeof cmd.path) return BAD("file name too long");
        snprintf(cmd.path, sizeof cmd.path, "%s", tok[1]);
        return add(p, &cmd);
    }
    if (!strcmp(c, "slow")) {
        if (n != 2 || !rs_parse_number(tok[1], 0, 60, &a[0])) return BAD("expected seconds per frame (0..60)");
        return add(p, &(vw_cmd){.type = VW_CMD_SLOW, .value = a[0]});
    }
    if (!strcmp(c, "drop") || !strcmp(c, "screenshot") || !strcmp(c, "wait-for")) {
        if (n != 2) return BAD(c[0] == 's' ? "expected FILE [X Y W H]" : "expected one file name (no spaces)");
        if (strlen(tok[1]) >= sizeof ((vw_event *)0)->path) return BAD("file name too long");
        if (c[0] == 'd') {
            vw_event ev = {.type = VW_DROP};
            snprintf(ev.path, sizeof ev.path, "%s", tok[1]);
            return add_event(p, ev, false);
        }
        vw_cmd cmd = {.type = c[0] == 's' ? VW_CMD_SCREENSHOT : VW_CMD_WAIT_FOR};
        snprintf(cmd.path, sizeof cmd.path, "%s", tok[1]);
        return add(p, &cmd);
    }
    if (!strcmp(c, "step") || !strcmp(c, "wait")) {
        if (n != 2 || !rs_parse_number(tok[1], 0, 3600, &a[0])) return BAD("expected seconds (0..3600)");
        return add(p, &(vw_cmd){.type = c[0] == 's' ? VW_CMD_STEP : VW_CMD_WAIT, .value = a[0]});
    }
    if (!strcmp(c, "frames")) {
        if (n != 2 || !rs_parse_number(tok[1], 1, 1e6, &a[0]) || a[0] != floor(a[0])) return BAD("expected a count (1..1000000)");
        return add(p, &(vw_cmd){.type = VW_CMD_FRAMES, .value = a[0]});
    }
    if (!strcmp(c, "idle") || !strcmp(c, "quit") || !strcmp(c, "loaded")) {
        if (n != 1) return BAD("takes no values");
        return add(p, &(vw_cmd){.type = c[0] == 'i' ? VW_CMD_IDLE : c[0] == 'q' ? VW_CMD_QUIT : VW_CMD_LOADED});
    }
#undef BAD
    return rs_fail(err, RS_ERR_FORMAT, "%s:%d: unknown command '%s' (see rouge --help, 'event scripts')", p->file,
                   p->line, c);
}

rs_result vw_script_load(const char *path, vw_script *out, rs_error *err)
{
    void *data = NULL;
    size_t len = 0;
    rs_result r = rs_file_read_all(path, VW_SCRIPT_MAX_BYTES, &data, &len, err);
    if (r) return r;
    vw_script s = {.step_s = 1.0 / 60.0};
    snprintf(s.name, sizeof s.name, "%s", path);
    parser p = {.s = &s, .file = path, .err = err};
    rs_text_reader t = {.data = data, .len = len};
    char buf[1024], *line;
    rs_result rr = RS_OK;  // the line reader's own failure ("line N: ...")
    while (!r && rs_text_next_line(&t, buf, sizeof buf, &line, &rr, err)) {
        p.line = (int)t.line;
        char *hash = strchr(line, '#');
        if (hash) *hash = 0;
        char *tok[8];
        int nt = 0;
        for (char *w = strtok(line, " \t\r"); w; w = strtok(NULL, " \t\r")) {
            if (nt == 8) {
                r = rs_fail(err, RS_ERR_FORMAT, "%s:%d: too many values", path, p.line);
                break;
            }
            tok[nt++] = w;
        }
        if (!r && nt) r = parse_line(&p, tok, nt);
    }
    free(data);
    if (rr) {
        rs_error inner = *err;
        r = rs_fail(err, rr, "%s: %s", path, inner.msg);
    }
    if (r) {
        free(s.cmd);
        return r;
    }
    *out = s;
    return RS_OK;
}

void vw_script_free(vw_script *s)
{
    free(s->cmd);
    s->cmd = NULL;
    s->count = s->next = 0;
}

void vw_script_run(vw_script *s, vw_queue *q, bool settled, bool loading, double now_s, vw_script_step *out)
{
    *out = (vw_script_step){0};
    if (s->done) return;
    if (s->frames_left > 0) {
        s->frames_left--;
        return;
    }
    if (now_s < s->wait_until) return;
    if (s->want_idle && !settled) return;
    s->want_idle = false;
    while (s->next < s->count) {
        const vw_cmd *c = &s->cmd[s->next];
        if (c->type != VW_CMD_EVENT) s->live_wall_s = -1;  // slow: the next event sets the clocks together
        switch (c->type) {
        case VW_CMD_EVENT: {
            if (q->count >= VW_QUEUE_CAP - 1) return;  // let the frame drain the queue first
            double t = s->clock_s + (c->advance ? s->step_s : 0);
            if (s->slow_s > 0) {
                if (s->live_wall_s < 0) s->live_wall_s = now_s, s->live_clock_s = s->clock_s;
                if (now_s < s->live_wall_s + (t - s->live_clock_s)) return;  // it has not happened yet
            }
            vw_event ev = c->ev;
            s->clock_s = ev.time_s = t;
            vw_queue_push(q, &ev);
            s->pushed++;
            s->next++;
            // Normally a button press or release ends the frame's batch (one step at a time, as a fast
            // machine sees a hand); under `slow` every event whose time has come goes into this frame.
            if (ev.type == VW_BUTTON && s->slow_s <= 0) return;
            break;
        }
        case VW_CMD_SLOW:
            s->slow_s = c->value;
            s->next++;
            break;
        case VW_CMD_STATE:
            out->state = c->path;
            s->next++;
            return;
        case VW_CMD_STEP:
            s->step_s = c->value;
            s->next++;
            break;
        case VW_CMD_FRAMES:
            s->frames_left = (int)c->value - 1;
            s->next++;
            return;
        case VW_CMD_WAIT:
            s->wait_until = now_s + c->value;
            s->clock_s += c->value;
            s->next++;
            return;
        case VW_CMD_IDLE:
            s->next++;
            if (!settled) {
                s->want_idle = true;
                return;
            }
            break;
        case VW_CMD_SCREENSHOT:
            // The frame must show everything pushed so far at full quality: wait for idle first.
            if (!settled || q->count) {
                s->want_idle = true;
                return;
            }
            out->screenshot = c->path;
            out->rect = c->rect;
            s->next++;
            return;
        case VW_CMD_WAIT_FOR:
            if (access(c->path, F_OK) != 0) return;
            s->next++;
            break;
        case VW_CMD_LOADED:
            if (loading) return;
            s->next++;
            break;
        case VW_CMD_QUIT:
            out->quit = true;
            s->done = true;
            s->next++;
            return;
        }
    }
    s->done = true;
}
