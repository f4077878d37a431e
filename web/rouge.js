// rouge.js — rouge in a web page: realistic skin and touch makeup on a face scan, in a WebGL 2 canvas.
// The web counterpart of rouge.h: the same C library, compiled to WebAssembly (rouge_core.wasm).
//
// DOES:
//   - load a face (.rsf) from a URL as a stream (its coarsest LOD level is drawn as soon as it arrives and
//     refines as levels complete; painting waits for the whole face) or from bytes;
//   - draw it into a canvas you own, sized by CSS (the drawing buffer follows the CSS size times the
//     device pixel ratio), redrawing only when something changed;
//   - take Pointer Events itself (input: true, the default): one finger or the mouse paints (paint mode) or
//     orbits (view mode); two fingers pinch-zoom around their midpoint, pan, and twist (turns the head); a
//     pen's pressure sets opacity, and while a pen is down touches are ignored (palm rejection); the wheel
//     zooms. Every event (getCoalescedEvents too) is queued and applied in order before the next frame:
//     none is dropped or merged away when frames are slow;
//   - brush, eraser, smudge and blend tools, mirror, region-aware painting, custom products, undo / redo / clear, looks as text,
//     a comparison look, pixels and PNG screenshots.
// DOES NOT:
//   - draw any controls (the page does: web/index.html), store looks (the page keeps them in
//     localStorage), or need special HTTP headers (no SharedArrayBuffer, no threads).
//
// Errors: promises reject with a RougeError (message, code: 'ROUGE_ERR_IO', ...); nothing throws later
// from a frame: frame failures reach onState('error: ...').
//
//   import { createRouge } from './rouge.js';
//   const rouge = await createRouge(document.querySelector('canvas'), {
//       face: 'face.rsf', view: { env: 'daylight', yaw: 20 }, brush: { cosmetic: 'lipstick_satin' } });
//   await rouge.setBrush({ cosmetic: 'blush', opacity: 0.5 });
//   const look = await rouge.saveLook();          // text of a .look file
//   rouge.destroy();
import createRougeCore from './rouge_core.js';

export class RougeError extends Error {
    constructor(message, code = 'ROUGE_ERR_ARG') {
        super(message);
        this.name = 'RougeError';
        this.code = code;
    }
}

const MODES = ['full', 'albedo', 'diffuse', 'specular', 'normals', 'regions', 'shadow', 'lod', 'irradiance'];
const PIPELINES = { default: 0, mobile: 1, reference: 2 };
const FINISHES = ['default', 'matte', 'satin', 'gloss', 'shimmer'];
const PRESSURES = ['floor', 'linear', 'none'];
const TOOLS = ['paint', 'smudge', 'blend'];  // rouge_tool
const POINTER = { down: 0, move: 1, up: 2, cancel: 3 };
const RESULT_NAMES = ['ROUGE_OK', 'ROUGE_ERR_IO', 'ROUGE_ERR_FORMAT', 'ROUGE_ERR_LIMIT', 'ROUGE_ERR_NOMEM',
                      'ROUGE_ERR_GL', 'ROUGE_ERR_ARG', 'ROUGE_ERR_CANCELLED'];
const ENV_DIR = '/env';
// A preview face costs a face creation (shaders, targets): only when the face is slow to arrive, and not
// more often than this.
const PREVIEW_AFTER_MS = 300;
const PREVIEW_EVERY_MS = 250;
const MAX_PIXEL_RATIO = 2;
const WHEEL_STEP = 1.12;       // zoom per wheel notch (100 px of deltaY)

const DEFAULT_VIEW = {
    yaw: 0, pitch: 0, zoom: 1, pan: [0, 0], env: 'studio', envRotation: 0, mode: 'full', pipeline: 'mobile',
    exposure: 1, hideMakeup: false, compareLook: false, kernelCount: 0, lodDensity: 0,
};
const DEFAULT_BRUSH = {
    cosmetic: 'lipstick_satin', color: null, finish: 'default', coverage: 0, size: 0, opacity: 0,
    pressure: 'floor', eraser: false, mirror: false, anyRegion: false, tool: 'paint',
};

let coreModule = null;  // the wasm module is stateless apart from the faces made in it: one per page

async function loadCore() {
    if (!coreModule) coreModule = createRougeCore({ print: () => {}, printErr: () => {} });
    return coreModule;
}

function hexColor(c) {
    if (c == null) return [0, 0, 0, 0];
    if (typeof c === 'string') {
        const m = /^#?([0-9a-f]{6})$/i.exec(c.trim());
        if (!m) throw new RougeError(`brush.color "${c}" is not #rrggbb`);
        const v = parseInt(m[1], 16);
        return [(v >> 16 & 255) / 255, (v >> 8 & 255) / 255, (v & 255) / 255, 1];
    }
    if (c.length < 3 || [...c].some((x) => !Number.isFinite(x) || x < 0 || x > 1))
        throw new RougeError('brush.color must be #rrggbb or [r, g, b(, a)] in 0..1');
    return [c[0], c[1], c[2], c.length > 3 ? c[3] : 1];
}

function enumIndex(table, value, what) {
    const i = table.indexOf(value);
    if (i < 0) throw new RougeError(`${what} "${value}" is not one of ${table.join(', ')}`);
    return i;
}

// The product table (pure data; no face needed).
export async function cosmetics() {
    const M = await loadCore();
    const out = [];
    const f = M._malloc(8 * 4);
    for (let i = 0; M._rw_cosmetic(i, f); i++) {
        const v = new Float32Array(M.HEAPU8.buffer, f, 8);
        out.push({
            name: M.UTF8ToString(M._rw_cosmetic_name(i)), kind: M.UTF8ToString(M._rw_cosmetic_kind(i)),
            rgb: [v[0], v[1], v[2]], size: v[3], opacity: v[4], finish: FINISHES[v[5]] || 'default',
            coverage: v[6], region: M.UTF8ToString(M._rw_cosmetic_region(i)) || null,
        });
    }
    M._free(f);
    return out;
}

// The bundled lighting environments (then "paper": the paper's single lamp).
export async function environments() {
    const M = await loadCore();
    const out = [];
    for (let i = 0, n = M._rouge_environment_count(); i < n; i++) out.push(M.UTF8ToString(M._rouge_environment_name(i)));
    return out;
}

// Creates rouge on `canvas`. Resolves once the whole face is loaded and drawn (previews are drawn while it
// streams); rejects with a RougeError (no WebGL 2, a face that cannot be fetched or is corrupt).
// options: face (URL, ArrayBuffer or Uint8Array; default the bundled face.rsf beside this file), envBase
// (URL of the .rse folder; default env/ beside this file), view, brush, painting (default true), input
// (default true), pixelRatio (default devicePixelRatio, at most 2), onProgress({stage, bytes, total,
// splats, ready, complete}), onState('loading' | 'busy' | 'ready' | 'error: ...'), frameDelayMs (tests:
// stalls every frame this long, as a slow device would).
export async function createRouge(canvas, options = {}) {
    if (!(canvas instanceof HTMLCanvasElement)) throw new RougeError('createRouge needs a <canvas> element');
    const r = new Rouge(canvas, options);
    try {
        await r._start();
    } catch (e) {
        r._setState(`error: ${e.message}`);
        r.destroy();
        throw e instanceof RougeError ? e : new RougeError(String(e.message || e), 'ROUGE_ERR_IO');
    }
    return r;
}

class Rouge {
    constructor(canvas, options) {
        this.canvas = canvas;
        this.options = options;
        this.view = { ...DEFAULT_VIEW, ...(options.view || {}) };
        this.brush = { ...DEFAULT_BRUSH, ...(options.brush || {}) };
        this.painting = options.painting !== false;
        this.queue = [];              // actions applied in order at the next frame
        this.pointers = new Map();    // pointerId -> {type, x, y} while down
        this.penDown = 0;
        this.twist = null;            // the two touches' angle, for twisting
        this.counts = { events: 0, applied: 0, frames: 0 };
        this.load = { firstDrawBytes: 0, firstDrawMs: 0, totalBytes: 0, totalMs: 0 };
        this.state = '';
        this.envs = new Set();
        this.dirty = true;
        this.raf = 0;
        this.destroyed = false;
        this.app = 0;
    }

    // ---- start-up ----

    async _start() {
        this._setState('loading');
        this._progress({ stage: 'module' });
        const M = this.M = await loadCore();
        if (!this.canvas.id) this.canvas.id = `rouge-canvas-${Math.random().toString(36).slice(2)}`;
        this._resize();
        this.app = M._rw_create(this._str(`#${this.canvas.id}`));
        if (!this.app) throw new RougeError('out of memory', 'ROUGE_ERR_NOMEM');
        this._check(M._rw_error_code(this.app));
        const base = this.options.base || new URL('.', import.meta.url);
        this.envBase = this.options.envBase ? new URL(this.options.envBase, location.href) : new URL('env/', base);
        try { M.FS.mkdir(ENV_DIR); } catch (e) { /* made by another face of this page */ }
        await this._fetchEnv(this.view.env);
        this._call(() => this._applyView());
        this._call(() => this._applyBrush());
        M._rw_set_painting(this.app, this.painting);
        if (this.options.input !== false) this._attachInput();
        this.resizeObserver = new ResizeObserver(() => { this.dirty = true; this._kick(); });
        this.resizeObserver.observe(this.canvas);
        const face = this.options.face ?? new URL('face.rsf', base).href;
        const t0 = performance.now();
        if (typeof face === 'string' || face instanceof URL) await this._stream(String(face), t0);
        else await this._fromBytes(face instanceof ArrayBuffer ? new Uint8Array(face) : face, t0);
        this._kick();
        await this.render();
    }

    async _fetchEnv(name) {
        if (!name || name === 'paper' || this.envs.has(name)) return;
        if (!/^[a-z0-9_-]+$/i.test(name)) throw new RougeError(`environment "${name}": not a bundled name`);
        const url = new URL(`${name}.rse`, this.envBase);
        let res;
        try {
            res = await fetch(url);
        } catch (e) {
            throw new RougeError(`environment ${url}: ${e.message}`, 'ROUGE_ERR_IO');
        }
        if (!res.ok) throw new RougeError(`environment ${url}: HTTP ${res.status} ${res.statusText}`, 'ROUGE_ERR_IO');
        this.M.FS.writeFile(`${ENV_DIR}/${name}.rse`, new Uint8Array(await res.arrayBuffer()));
        this.envs.add(name);
    }

    async _stream(url, t0) {
        const M = this.M;
        let res;
        try {
            res = await fetch(url);
        } catch (e) {
            throw new RougeError(`face ${url}: cannot be fetched (${e.message})`, 'ROUGE_ERR_IO');
        }
        if (!res.ok) throw new RougeError(`face ${url}: HTTP ${res.status} ${res.statusText || ''}`.trim(), 'ROUGE_ERR_IO');
        // Content-Length is the file's size only when the body is not content-encoded.
        const total = res.headers.get('content-encoding') ? 0 : Number(res.headers.get('content-length')) || 0;
        const name = decodeURIComponent(new URL(url, location.href).pathname.split('/').pop() || 'face');
        this._call(() => M._rw_stream_begin(this.app, this._str(name), total));
        const reader = res.body.getReader();
        let shown = 0, lastPreview = 0, bytes = 0;
        for (;;) {
            const { done, value } = await reader.read();
            if (this.destroyed) { reader.cancel(); throw new RougeError('destroyed while loading'); }
            if (done) break;
            bytes += value.length;
            this._withBytes(value, (p, n) => this._call(() => M._rw_stream_feed(this.app, p, n)));
            const p = this._streamProgress();
            this._progress({ stage: 'face', bytes: p.bytes, total, splats: p.splats, ready: p.ready, complete: p.complete });
            const now = performance.now();
            if (!p.complete && p.ready > shown && now - t0 >= PREVIEW_AFTER_MS &&
                (!shown || now - lastPreview >= PREVIEW_EVERY_MS)) {
                this._call(() => M._rw_face_from_stream(this.app, this._str(ENV_DIR)));
                shown = p.ready;
                lastPreview = now;
                this._draw();
                if (!this.load.firstDrawBytes) this.load.firstDrawBytes = bytes, this.load.firstDrawMs = performance.now() - t0;
                await new Promise((ok) => requestAnimationFrame(ok));  // let the preview reach the screen
            }
        }
        const p = this._streamProgress();
        if (!p.complete) throw new RougeError(`face ${url}: the file ended early (${bytes} bytes)`, 'ROUGE_ERR_FORMAT');
        this._progress({ stage: 'building', bytes, total, splats: p.splats, ready: p.splats, complete: true });
        this._call(() => M._rw_face_from_stream(this.app, this._str(ENV_DIR)));
        this._draw();
        if (!this.load.firstDrawBytes) this.load.firstDrawBytes = bytes, this.load.firstDrawMs = performance.now() - t0;
        this.load.totalBytes = bytes;
        this.load.totalMs = performance.now() - t0;
        this._progress({ stage: 'done', bytes, total, splats: p.splats, ready: p.splats, complete: true });
    }

    async _fromBytes(bytes, t0) {
        if (!(bytes instanceof Uint8Array)) throw new RougeError('face must be a URL, an ArrayBuffer or a Uint8Array');
        this._withBytes(bytes, (p, n) => this._call(() => this.M._rw_face_from_bytes(this.app, p, n, this._str(ENV_DIR))));
        this._draw();
        this.load = { firstDrawBytes: bytes.length, firstDrawMs: performance.now() - t0, totalBytes: bytes.length,
                      totalMs: performance.now() - t0 };
        this._progress({ stage: 'done', bytes: bytes.length, total: bytes.length, complete: true });
    }

    _streamProgress() {
        const M = this.M, f = M._malloc(5 * 8);
        M._rw_stream_progress(this.app, f);
        const v = new Float64Array(M.HEAPU8.buffer, f, 5);
        const p = { bytes: v[0], splats: v[1], decoded: v[2], ready: v[3], complete: !!v[4] };
        M._free(f);
        return p;
    }

    // ---- the C side ----

    _str(s) {  // a C string valid until the next frame's strings are freed
        const M = this.M, n = M.lengthBytesUTF8(s) + 1, p = M._malloc(n);
        M.stringToUTF8(s, p, n);
        (this.strings ||= []).push(p);
        return p;
    }

    _freeStrings() {
        for (const p of this.strings || []) this.M._free(p);
        this.strings = [];
    }

    _withBytes(bytes, fn) {
        const M = this.M, p = M._malloc(Math.max(1, bytes.length));
        if (!p) throw new RougeError('out of memory', 'ROUGE_ERR_NOMEM');
        try {
            M.HEAPU8.set(bytes, p);
            return fn(p, bytes.length);
        } finally {
            M._free(p);
        }
    }

    _check(code) {
        if (!code) return;
        const M = this.M;
        const msg = M.UTF8ToString(M._rw_error_message(this.app));
        M._rw_error_clear(this.app);
        throw new RougeError(msg, RESULT_NAMES[code] || 'ROUGE_ERR_GL');
    }

    _call(fn) {
        try {
            this._check(fn());
        } finally {
            this._freeStrings();
        }
    }

    _applyView() {
        const v = this.view;
        const mode = enumIndex(MODES, v.mode, 'view.mode');
        if (!(v.pipeline in PIPELINES)) throw new RougeError(`view.pipeline "${v.pipeline}" is not mobile or reference`);
        for (const k of ['yaw', 'pitch', 'zoom', 'envRotation', 'exposure', 'kernelCount', 'lodDensity'])
            if (!Number.isFinite(v[k])) throw new RougeError(`view.${k} must be a finite number`);
        if (!Array.isArray(v.pan) || !v.pan.every(Number.isFinite)) throw new RougeError('view.pan must be [x, y]');
        return this.M._rw_set_view(this.app, 0, 0, v.yaw, v.pitch, v.zoom, v.pan[0], v.pan[1], this._str(v.env || ''),
                                   v.envRotation, mode, PIPELINES[v.pipeline], v.exposure, v.hideMakeup, v.compareLook,
                                   v.kernelCount, v.lodDensity);
    }

    _applyBrush() {
        const b = this.brush;
        const c = hexColor(b.color);
        for (const k of ['coverage', 'size', 'opacity'])
            if (!Number.isFinite(b[k])) throw new RougeError(`brush.${k} must be a finite number`);
        return this.M._rw_set_brush(this.app, this._str(b.cosmetic || ''), c[0], c[1], c[2], c[3],
                                    enumIndex(FINISHES, b.finish, 'brush.finish'), b.coverage, b.size, b.opacity,
                                    enumIndex(PRESSURES, b.pressure, 'brush.pressure'), b.eraser, b.mirror, b.anyRegion,
                                    enumIndex(TOOLS, b.tool || 'paint', 'brush.tool'));
    }

    // ---- the queue and the frame ----

    // Queues fn (applied in order before the next frame); resolves with its result.
    _enqueue(fn) {
        if (this.destroyed) return Promise.reject(new RougeError('this rouge was destroyed'));
        if (this.load.totalMs > 0) this._setState('busy');  // at once: a caller waiting for 'ready' waits for this
        return new Promise((resolve, reject) => {
            this.queue.push({ fn, resolve, reject });
            this._kick();
        });
    }

    _kick() {
        if (!this.raf && !this.destroyed) this.raf = requestAnimationFrame(() => this._frame());
    }

    _frame() {
        this.raf = 0;
        if (this.destroyed || !this.M) return;
        const q = this.queue;
        this.queue = [];
        for (const a of q) {
            try {
                a.resolve(a.fn());
            } catch (e) {
                a.reject(e);
            } finally {
                this._freeStrings();
            }
        }
        if (this.M._rw_has_face(this.app) && (this.dirty || this.M._rw_changed(this.app))) {
            try {
                this._draw();
            } catch (e) {
                this._setState(`error: ${e.message}`);
                return;
            }
            if (this.options.frameDelayMs > 0) {  // tests: a slow device
                const until = performance.now() + this.options.frameDelayMs;
                while (performance.now() < until) { /* stall */ }
            }
        }
        for (const w of this.frameWaiters || []) w();
        this.frameWaiters = [];
        const settled = !this.queue.length && !this.pointers.size && this.load.totalMs > 0 &&
                        !this.M._rw_is_preview(this.app);
        this._setState(settled ? 'ready' : (this.load.totalMs > 0 ? 'busy' : 'loading'));
        if (this.queue.length) this._kick();
    }

    _resize() {
        const c = this.canvas;
        const ratio = Math.min(this.options.pixelRatio || window.devicePixelRatio || 1, MAX_PIXEL_RATIO);
        const w = Math.max(1, Math.round((c.clientWidth || c.width) * ratio));
        const h = Math.max(1, Math.round((c.clientHeight || c.height) * ratio));
        if (c.width !== w || c.height !== h) c.width = w, c.height = h;
    }

    _draw() {
        this._resize();
        this._check(this.M._rw_draw(this.app, this.canvas.width, this.canvas.height));
        // The frame's size, which pointer coordinates refer to: read once per frame, not per event.
        const s = this.stats();
        this.frameW = s.width, this.frameH = s.height;
        this.dirty = false;
        this.counts.frames++;
    }

    _setState(s) {
        if (s === this.state) return;
        this.state = s;
        this.options.onState?.(s);
    }

    _progress(p) { this.options.onProgress?.(p); }

    // ---- input ----

    // CSS pixels relative to the canvas -> pixels of the last frame (what rouge's picks and gestures use).
    _toFrame(x, y) {
        const c = this.canvas, w = this.frameW || c.width, h = this.frameH || c.height;
        return [x * w / Math.max(1, c.clientWidth || c.width), y * h / Math.max(1, c.clientHeight || c.height)];
    }

    // Feeds one pointer event: {type: 'down'|'move'|'up'|'cancel', id, x, y (CSS px from the canvas's
    // top-left), pressure (0..1; 0 = 1), time (ms, performance.now())}. Queued; resolves with
    // {stamps, misses, strokeBegin, strokeEnd, strokeCancel}.
    pointer(ev) {
        const type = POINTER[ev.type];
        if (type === undefined) return Promise.reject(new RougeError(`pointer type "${ev.type}" is not down, move, up or cancel`));
        if (![ev.x, ev.y].every(Number.isFinite)) return Promise.reject(new RougeError('pointer x and y must be finite'));
        this.counts.events++;
        return this._enqueue(() => {
            const M = this.M;
            const [x, y] = this._toFrame(ev.x, ev.y);
            this.counts.applied++;
            this._check(M._rw_pointer(this.app, type, ev.id | 0, x, y, ev.pressure || 0, (ev.time ?? performance.now()) / 1000));
            const f = M._malloc(10 * 4);
            M._rw_pointer_result(this.app, f);
            const v = new Float32Array(M.HEAPU8.buffer, f, 10);
            const out = { stamps: v[0], misses: v[1], strokeBegin: !!v[2], strokeEnd: !!v[3], strokeCancel: !!v[4] };
            M._free(f);
            return out;
        });
    }

    _attachInput() {
        const c = this.canvas;
        c.style.touchAction = 'none';  // the page must not scroll or zoom under a finger
        const local = (e) => {
            const r = c.getBoundingClientRect();
            return [e.clientX - r.left, e.clientY - r.top];
        };
        const send = (type, e) => {
            const [x, y] = local(e);
            // A pen's pressure sets opacity; a mouse reports 0.5 while a button is down: full strength.
            const pressure = e.pointerType === 'pen' || e.pointerType === 'touch' ? (e.pressure || 0.5) : 1;
            this.pointer({ type, id: e.pointerId, x, y, pressure, time: e.timeStamp }).catch((err) => this._setState(`error: ${err.message}`));
        };
        const twist = () => {  // two touches: their angle's change turns the head about its vertical axis
            const t = [...this.pointers.values()].filter((p) => p.type === 'touch');
            if (t.length !== 2) { this.twist = null; return; }
            const a = Math.atan2(t[1].y - t[0].y, t[1].x - t[0].x) * 180 / Math.PI;
            if (this.twist !== null) {
                let d = a - this.twist;
                d -= 360 * Math.round(d / 360);
                if (Math.abs(d) > 0.01) this._enqueue(() => this.M._rw_orbit(this.app, d, 0));
            }
            this.twist = a;
        };
        this.listeners = {
            pointerdown: (e) => {
                if (e.pointerType === 'touch' && this.penDown) return;  // palm rejection
                if (e.pointerType === 'pen') {
                    this.penDown++;
                    for (const [id, p] of this.pointers)  // a palm that landed first: its stroke is rolled back
                        if (p.type === 'touch') { this.pointers.delete(id); this.pointer({ type: 'cancel', id, x: p.x, y: p.y }); }
                }
                const [x, y] = local(e);
                this.pointers.set(e.pointerId, { type: e.pointerType, x, y });
                c.setPointerCapture?.(e.pointerId);
                send('down', e);
                twist();
                e.preventDefault();
            },
            pointermove: (e) => {
                const p = this.pointers.get(e.pointerId);
                if (!p) return;
                const all = e.getCoalescedEvents ? e.getCoalescedEvents() : [];
                for (const ce of all.length ? all : [e]) {
                    send('move', ce);
                    [p.x, p.y] = local(ce);
                    twist();
                }
                e.preventDefault();
            },
            pointerup: (e) => this._pointerEnd(e, 'up', send, twist),
            pointercancel: (e) => this._pointerEnd(e, 'cancel', send, twist),
            wheel: (e) => {
                const [x, y] = local(e);
                const f = Math.pow(WHEEL_STEP, -e.deltaY / 100);
                this.zoomAt(f, x, y);
                e.preventDefault();
            },
        };
        for (const [k, fn] of Object.entries(this.listeners)) c.addEventListener(k, fn, { passive: false });
    }

    _pointerEnd(e, type, send, twist) {
        if (!this.pointers.has(e.pointerId)) return;
        this.pointers.delete(e.pointerId);
        if (e.pointerType === 'pen') this.penDown = Math.max(0, this.penDown - 1);
        send(type, e);
        twist();
    }

    // ---- the public methods (all mutating ones are queued and applied in order) ----

    // Merges `v` into the view ({yaw, pitch, zoom, pan: [x, y], env, envRotation, mode, pipeline, exposure,
    // hideMakeup, compareLook, kernelCount, lodDensity}); fetches a bundled environment on first use.
    async setView(v) {
        if (v.env && v.env !== this.view.env) await this._fetchEnv(v.env);
        return this._enqueue(() => {
            const cur = this.getView();
            const next = { ...this.view, yaw: cur.yaw, pitch: cur.pitch, zoom: cur.zoom, pan: cur.pan, ...v };
            const old = this.view;
            this.view = next;
            try {
                this._call(() => this._applyView());
            } catch (e) {
                this.view = old;
                throw e;
            }
            this.dirty = true;
        });
    }

    // The view, with the camera as navigation left it.
    getView() {
        const M = this.M;
        if (!M || !this.app) return { ...this.view };
        const f = M._malloc(8 * 4);
        M._rw_get_view(this.app, f);
        const a = new Float32Array(M.HEAPU8.buffer, f, 8);
        const out = { ...this.view, yaw: a[0], pitch: a[1], zoom: a[2] || 1, pan: [a[3], a[4]], envRotation: a[7] };
        M._free(f);
        return out;
    }

    // Merges `b` into the brush ({cosmetic, color: '#rrggbb' | [r, g, b, a] | null, finish, coverage, size,
    // opacity, pressure: 'floor'|'linear'|'none', eraser, mirror, anyRegion, tool: 'paint'|'smudge'|'blend'}).
    // tool (rouge_brush.tool): smudge drags the makeup on the face along the stroke, blend softens its edges;
    // opacity is then the tool's strength (0: 0.8), and the eraser must be off.
    setBrush(b) {
        return this._enqueue(() => {
            const old = this.brush;
            this.brush = { ...this.brush, ...b };
            try {
                this._call(() => this._applyBrush());
            } catch (e) {
                this.brush = old;
                throw e;
            }
        });
    }

    getBrush() { return { ...this.brush }; }

    // true: one pointer paints; false: it orbits. Two pointers always pinch, pan and twist.
    setPainting(on) {
        return this._enqueue(() => { this.painting = !!on; this.M._rw_set_painting(this.app, this.painting); });
    }

    orbit(yawDeg, pitchDeg) { return this._enqueue(() => this.M._rw_orbit(this.app, yawDeg, pitchDeg)); }
    pan(dx, dy) {  // CSS pixels
        return this._enqueue(() => { const [x, y] = this._toFrame(dx, dy); this.M._rw_pan(this.app, x, y); });
    }
    zoomAt(factor, x, y) {  // keeps the CSS point (x, y) in place
        if (!(factor > 0) || !Number.isFinite(factor)) return Promise.reject(new RougeError('zoom factor must be > 0'));
        return this._enqueue(() => { const [fx, fy] = this._toFrame(x, y); this.M._rw_zoom_at(this.app, factor, fx, fy); });
    }
    // Frames a region ("lips", "eyes", "cheek", ... as the face's region table names them).
    target(region, fill = 0) { return this._enqueue(() => this._call(() => this.M._rw_target(this.app, this._str(region), fill))); }

    undo() { return this._enqueue(() => !!this.M._rw_undo(this.app)); }
    redo() { return this._enqueue(() => !!this.M._rw_redo(this.app)); }
    clear() { return this._enqueue(() => this._call(() => this.M._rw_clear(this.app))); }

    // A look: the text of a .look file (string) or its bytes. Clears undo.
    loadLook(look) {
        const bytes = typeof look === 'string' ? new TextEncoder().encode(look) : new Uint8Array(look);
        return this._enqueue(() => this._withBytes(bytes, (p, n) => this._call(() => this.M._rw_load_look(this.app, p, n))));
    }

    // The current look as the text of a .look file.
    saveLook() {
        return this._enqueue(() => {
            const M = this.M, sp = M._malloc(4);
            try {
                const p = M._rw_save_look(this.app, sp);
                if (!p) this._check(M._rw_error_code(this.app) || 6);
                const n = new Uint32Array(M.HEAPU8.buffer, sp, 1)[0];
                const text = new TextDecoder().decode(M.HEAPU8.slice(p, p + n));
                M._rouge_free(p);
                return text;
            } finally {
                M._free(sp);
            }
        });
    }

    // A second look shown when view.compareLook is set (text of a .look file), or null: the bare face.
    setCompareLook(look) {
        return this._enqueue(() => {
            const path = '/compare.look';
            if (look != null) this.M.FS.writeFile(path, typeof look === 'string' ? look : new Uint8Array(look));
            this._call(() => this.M._rw_set_compare_look(this.app, look != null ? this._str(path) : 0));
            this.dirty = true;
        });
    }

    // Resolves after every queued action was applied and the frame drawn.
    render() {
        this.dirty = true;
        return new Promise((ok) => {
            (this.frameWaiters ||= []).push(ok);
            this._kick();
        });
    }

    // The last frame: {width, height, data: Uint8ClampedArray RGBA, rows top-first}.
    readPixels() {
        const s = this.stats(), n = s.width * s.height * 4;
        if (!n) throw new RougeError('no frame yet');
        const M = this.M, p = M._malloc(n);
        try {
            this._check(M._rw_read_rgba(this.app, p, n));
            return { width: s.width, height: s.height, data: new Uint8ClampedArray(M.HEAPU8.slice(p, p + n).buffer) };
        } finally {
            M._free(p);
        }
    }

    // The last frame as a PNG Blob (full resolution).
    async toBlob() {
        const px = this.readPixels();
        const c = document.createElement('canvas');
        c.width = px.width, c.height = px.height;
        c.getContext('2d').putImageData(new ImageData(px.data, px.width, px.height), 0, 0);
        return new Promise((ok) => c.toBlob(ok, 'image/png'));
    }

    // The surface under CSS point (x, y): {splat, position: [x, y, z], region} or null.
    pick(x, y) {
        const M = this.M, f = M._malloc(5 * 4), [fx, fy] = this._toFrame(x, y);
        try {
            if (!M._rw_pick(this.app, fx, fy, f)) return null;
            const v = new Float32Array(M.HEAPU8.buffer, f, 5);
            return { splat: v[0], position: [v[1], v[2], v[3]], region: v[4] };
        } finally {
            M._free(f);
        }
    }

    // Statistics of the face and the last frame, plus events queued / applied (input is never dropped).
    stats() {
        const M = this.M;
        if (!M || !this.app) return { width: 0, height: 0 };
        const f = M._malloc(14 * 8);
        M._rw_stats(this.app, f);
        const v = new Float64Array(M.HEAPU8.buffer, f, 14);
        const s = {
            splats: v[0], splatsDrawn: v[1], width: v[2], height: v[3], frameMs: v[4], canUndo: !!v[5],
            canRedo: !!v[6], inStroke: !!v[7], lookStamps: v[8], faceHeightMm: v[9], lodCount: v[10],
            floatTargets: !!v[11], kernelCount: v[12], autoSplats: v[13], events: this.counts.events,
            eventsApplied: this.counts.applied, frames: this.counts.frames, queued: this.queue.length,
            preview: !!M._rw_is_preview(this.app), load: { ...this.load },
        };
        M._free(f);
        return s;
    }

    destroy() {
        if (this.destroyed) return;
        this.destroyed = true;
        if (this.raf) cancelAnimationFrame(this.raf);
        this.resizeObserver?.disconnect();
        for (const [k, fn] of Object.entries(this.listeners || {})) this.canvas.removeEventListener(k, fn);
        for (const a of this.queue) a.reject(new RougeError('this rouge was destroyed'));
        this.queue = [];
        if (this.M && this.app) this.M._rw_destroy(this.app);
        this.app = 0;
    }
}
