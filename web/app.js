// app.js — rouge's viewer page: wires index.html's controls to rouge.js. No framework, no build step.
//
// The contract (tests and embedders rely on it):
//   query: face=URL (default the bundled face.rsf), env=NAME, yaw=DEG, pitch=DEG, zoom=F, size=WxH (the
//     canvas in CSS px; without it the canvas fills the window), pipeline=mobile|reference, mode=view|paint,
//     brush=PRESET (a cosmetic's name), ui=0 (only the canvas, at the top-left), slow=MS (every frame
//     stalls this long: tests of slow devices). An invalid value ends in an error naming the parameter.
//   <html data-rouge-state>: "loading", then "ready" once the first full-quality frame is on screen and
//     again whenever an interaction has settled, "busy" while input is applied, or "error: MESSAGE" (also
//     shown on the page).
//   window.rouge: the Rouge instance (rouge.js), once it is ready.
import { createRouge, cosmetics, environments, RougeError } from './rouge.js';

const $ = (s) => document.querySelector(s);
const root = document.documentElement;
const canvas = $('#face');

const LOOKS_KEY = 'rouge.looks';
const SIZE_MIN = 0.02, SIZE_MAX = 0.40;  // brush diameter / face height at the size slider's ends (log scale)
const SMUDGE_STRENGTH = 0.8;  // a smudge or blend brush's opacity when none is set (RS_SMUDGE_STRENGTH_DEFAULT)
const ORBIT_STEP = 10;                   // degrees per arrow key
const ZOOM_STEP = 1.12;
const HOLD_MS = 350;                     // a longer press on before/after shows the bare face only while held
const FINISHES = ['matte', 'satin', 'gloss', 'shimmer'];

// ---- the query string ----

function number(q, key, ok = Number.isFinite, what = 'a number') {
    if (!q.has(key)) return undefined;
    const s = q.get(key).trim(), v = Number(s);
    if (s === '' || !ok(v)) throw new RougeError(`query parameter ${key}="${q.get(key)}" is not ${what}`);
    return v;
}

function oneOf(q, key, values) {
    if (!q.has(key)) return undefined;
    const v = q.get(key);
    if (!values.includes(v)) throw new RougeError(`query parameter ${key}="${v}" is not one of ${values.join(', ')}`);
    return v;
}

// What the query asks for; env and brush are checked against the bundled lists later (checkNames).
function parseQuery(search) {
    const q = new URLSearchParams(search);
    const out = {
        face: q.get('face') || undefined,
        env: q.has('env') ? q.get('env') : undefined,
        brush: q.has('brush') ? q.get('brush') : undefined,
        yaw: number(q, 'yaw', Number.isFinite, 'a number of degrees'),
        pitch: number(q, 'pitch', (v) => Number.isFinite(v) && Math.abs(v) <= 90, 'a number of degrees in -90..90'),
        zoom: number(q, 'zoom', (v) => Number.isFinite(v) && v > 0 && v <= 100, 'a zoom factor > 0'),
        pipeline: oneOf(q, 'pipeline', ['mobile', 'reference']),
        mode: oneOf(q, 'mode', ['paint', 'view']) || 'paint',
        ui: oneOf(q, 'ui', ['0', '1']) !== '0',
        slow: number(q, 'slow', (v) => Number.isFinite(v) && v >= 0 && v <= 60000, 'a delay in ms (0..60000)'),
        size: null,
    };
    if (q.has('size')) {
        const m = /^\s*(\d{1,5})\s*[x×]\s*(\d{1,5})\s*$/i.exec(q.get('size'));
        const w = m && +m[1], h = m && +m[2];
        if (!m || w < 1 || h < 1 || w > 8192 || h > 8192)
            throw new RougeError(`query parameter size="${q.get('size')}" is not WxH in CSS pixels (e.g. 320x320)`);
        out.size = [w, h];
    }
    return out;
}

function checkNames(opts, envs, products) {
    if (opts.env !== undefined && !envs.includes(opts.env))
        throw new RougeError(`query parameter env="${opts.env}" is not a bundled environment (${envs.join(', ')})`);
    if (opts.brush !== undefined && !products.some((p) => p.name === opts.brush))
        throw new RougeError(`query parameter brush="${opts.brush}" is not a cosmetic (${products.map((p) => p.name).join(', ')})`);
}

function hasWebGL2() {
    try {
        const gl = document.createElement('canvas').getContext('webgl2');
        gl?.getExtension('WEBGL_lose_context')?.loseContext();
        return !!gl;
    } catch (e) {
        return false;
    }
}

// ---- state: <html data-rouge-state> mirrors rouge's, "busy" while the page's own actions run ----

let rouge = null;
let engineState = 'loading';
let pending = 0;

function showState() {
    let s = engineState;
    if (!s.startsWith('error')) {
        if (!rouge) s = 'loading';          // ready only once window.rouge is there to be used
        else if (pending > 0) s = 'busy';
    }
    if (root.dataset.rougeState !== s) root.dataset.rougeState = s;
    if (s.startsWith('error')) showError(s.slice(7));
    else if (s === 'ready') refresh();
}

function onState(s) {
    engineState = s;
    showState();
}

function showError(message) {
    const text = `${message}`.replace(/^error:\s*/, '');
    root.dataset.rougeState = `error: ${text}`;
    $('#error-text').textContent = text;
    $('#error h1').textContent = rouge ? 'rouge stopped' : 'rouge could not start';
    $('#error .hint').textContent = rouge ? 'Reload the page to start again; your saved looks are kept.'
        : text.startsWith('query parameter')
        ? 'Check the address: face, env, yaw, pitch, zoom, size, pipeline, mode, brush, ui and slow take the values above.'
        : /WebGL/.test(text) ? 'rouge needs WebGL 2: try an up-to-date Chrome, Edge, Firefox or Safari, with hardware acceleration on.'
        : 'Check that the face’s address is right and that it is a rouge .rsf face.';
    $('#error').hidden = false;
    $('#loader').hidden = true;
}

// Runs one of the page's actions: busy until it settles; a failure is a message, not an error state.
async function act(promise, what) {
    pending++;
    showState();
    try {
        return await promise;
    } catch (e) {
        toast(`${what}: ${e.message}`, true);
        return undefined;
    } finally {
        pending--;
        showState();
    }
}

let toastTimer = 0;
function toast(text, bad = false) {
    const t = $('#toast');
    t.textContent = text;
    t.classList.toggle('bad', bad);
    t.classList.add('show');
    clearTimeout(toastTimer);
    toastTimer = setTimeout(() => t.classList.remove('show'), bad ? 5000 : 2500);
}

// ---- loading progress ----

const mb = (n) => (n / 1048576).toFixed(1);

function onProgress(p) {
    const loader = $('#loader'), bar = $('#loader-bar');
    let label = 'Starting…', detail = '', pct = null;
    if (p.stage === 'face') {
        label = p.ready ? 'Refining the face…' : 'Loading the face…';
        if (p.total) pct = Math.min(99, Math.floor(100 * p.bytes / p.total)), detail = `${mb(p.bytes)} / ${mb(p.total)} MB`;
        else detail = `${mb(p.bytes)} MB`;
    } else if (p.stage === 'building' || p.stage === 'done') {
        label = 'Preparing the skin…';
        pct = 100;
    }
    loader.classList.toggle('preview', !!p.ready);
    loader.classList.toggle('indeterminate', pct === null);
    bar.style.width = pct === null ? '' : `${pct}%`;
    if (pct === null) loader.removeAttribute('aria-valuenow');
    else loader.setAttribute('aria-valuenow', pct);
    loader.setAttribute('aria-valuetext', `${label} ${detail}`);
    $('#loader-label').textContent = label;
    $('#loader-detail').textContent = pct === null ? detail : `${pct}% · ${detail}`.replace(/ · $/, '');
}

// ---- the page's model of the brush and view (rouge holds the truth; this is what the controls show) ----

const ui = {
    products: [], envs: [], product: null,
    edit: { color: null, finish: 'default', coverage: 0 },  // the product editor's changes to the preset
    size: 0, opacity: 0,                                     // 0: the product's own
    eraser: false, mirror: false, anyRegion: false, painting: true, hide: false,
    tool: 'paint',                                           // 'smudge' | 'blend': move / soften the makeup
    env: 'studio', envRotation: 0, pipeline: 'mobile', start: {},
};

const pretty = (s) => s.replace(/_/g, ' ').replace(/^./, (c) => c.toUpperCase());
const hex = (rgb) => `#${rgb.map((v) => Math.round(v).toString(16).padStart(2, '0')).join('')}`;
const sizeOf = () => ui.size || ui.product.size;
const opacityOf = () => ui.opacity || (ui.tool === 'paint' ? ui.product.opacity : SMUDGE_STRENGTH);
const sizeToSlider = (s) => 1000 * Math.log(Math.min(Math.max(s, SIZE_MIN), SIZE_MAX) / SIZE_MIN) / Math.log(SIZE_MAX / SIZE_MIN);
const sliderToSize = (v) => SIZE_MIN * Math.pow(SIZE_MAX / SIZE_MIN, v / 1000);
const isCustom = () => ui.edit.color !== null || ui.edit.finish !== 'default' || ui.edit.coverage !== 0;

function setBrush(b, what = 'Brush') {
    if (rouge) act(rouge.setBrush(b), what);
}

function setView(v, what = 'View') {
    if (rouge) return act(rouge.setView(v), what);
    return Promise.resolve();
}

function pressed(el, on) { el.setAttribute('aria-pressed', on ? 'true' : 'false'); }

// ---- building the controls ----

function buildSwatches() {
    const box = $('#swatches');
    const kinds = [...new Set(ui.products.map((p) => p.kind))];
    for (const kind of kinds) {
        const group = document.createElement('div');
        group.className = 'group';
        group.setAttribute('role', 'presentation');
        const label = document.createElement('span');
        label.className = 'group-label';
        label.textContent = pretty(kind);
        label.setAttribute('aria-hidden', 'true');
        const row = document.createElement('div');
        row.className = 'group-row';
        row.setAttribute('role', 'presentation');
        for (const p of ui.products.filter((x) => x.kind === kind)) {
            const b = document.createElement('button');
            b.type = 'button';
            b.className = `swatch ${p.finish}${p.rgb.every((v) => v >= 250) ? ' clear' : ''}`;
            b.setAttribute('role', 'radio');
            b.setAttribute('aria-checked', 'false');
            b.setAttribute('aria-label', pretty(p.name));
            b.title = pretty(p.name);
            b.dataset.name = p.name;
            b.style.setProperty('--c', hex(p.rgb));
            b.append(document.createElement('i'));
            b.addEventListener('click', () => pickProduct(p));
            row.append(b);
        }
        group.append(label, row);
        box.append(group);
    }
    // Arrow keys move between products (one tab stop for the radio group).
    box.addEventListener('keydown', (e) => {
        const step = { ArrowRight: 1, ArrowDown: 1, ArrowLeft: -1, ArrowUp: -1 }[e.key];
        if (!step) return;
        e.preventDefault();
        e.stopPropagation();
        const i = ui.products.indexOf(ui.product);
        pickProduct(ui.products[(i + step + ui.products.length) % ui.products.length]);
        box.querySelector('[aria-checked="true"]')?.focus();
    });
}

function buildEnvs() {
    const box = $('#envs');
    for (const name of ui.envs) {
        const b = document.createElement('button');
        b.type = 'button';
        b.setAttribute('role', 'radio');
        b.dataset.env = name;
        b.textContent = name === 'paper' ? 'Paper lamp' : name;
        b.addEventListener('click', () => pickEnv(name));
        box.append(b);
    }
}

function buildFinishes() {
    const box = $('#finish');
    for (const f of FINISHES) {
        const b = document.createElement('button');
        b.type = 'button';
        b.setAttribute('role', 'radio');
        b.dataset.finish = f;
        b.textContent = pretty(f);
        b.addEventListener('click', () => {
            ui.edit.finish = f === ui.product.finish ? 'default' : f;
            setBrush({ finish: ui.edit.finish }, 'Finish');
            syncControls();
        });
        box.append(b);
    }
}

// ---- actions ----

// Brings the chosen product into the tray's view when the tray scrolls sideways (a phone upright).
function showSwatch() {
    const box = $('#swatches'), el = box.querySelector('[aria-checked="true"]');
    if (!el || box.scrollWidth <= box.clientWidth) return;
    // Centred, like a native picker (.swatches is the swatches' offsetParent).
    box.scrollTo({ left: el.offsetLeft - (box.clientWidth - el.offsetWidth) / 2, behavior: rouge ? 'smooth' : 'auto' });
}

function pickProduct(p) {
    ui.product = p;
    ui.edit = { color: null, finish: 'default', coverage: 0 };
    ui.size = 0, ui.opacity = 0;
    ui.eraser = false;
    ui.tool = 'paint';
    setBrush({ cosmetic: p.name, color: null, finish: 'default', coverage: 0, size: 0, opacity: 0, eraser: false, tool: 'paint' }, 'Product');
    if (!ui.painting) setPainting(true);
    syncControls();
    showSwatch();
}

function setPainting(on) {
    ui.painting = on;
    if (rouge) act(rouge.setPainting(on), 'Mode');
    syncControls();
}

function toggle(key, brushKey = key) {
    ui[key] = !ui[key];
    if (key === 'eraser' && ui.eraser && ui.tool !== 'paint') {
        ui.tool = 'paint';
        setBrush({ tool: 'paint', eraser: true });
    } else {
        setBrush({ [brushKey]: ui[key] });
    }
    if (key === 'eraser' && ui.eraser && !ui.painting) setPainting(true);
    syncControls();
}

// Smudge or blend on (the eraser off), or the same again: back to the product.
function setTool(t) {
    ui.tool = ui.tool === t ? 'paint' : t;
    ui.eraser = false;
    setBrush({ tool: ui.tool, eraser: false }, 'Tool');
    if (ui.tool !== 'paint' && !ui.painting) setPainting(true);
    if (ui.tool === 'smudge') toast('Smudge: drag from the makeup to carry it along');
    else if (ui.tool === 'blend') toast('Blend: brush over an edge to soften it');
    syncControls();
}

function setSize(s) {
    ui.size = Math.min(Math.max(s, SIZE_MIN), SIZE_MAX);
    setBrush({ size: ui.size }, 'Size');
    syncControls();
}

function setOpacity(o) {
    ui.opacity = Math.min(Math.max(o, 0.02), 1);
    setBrush({ opacity: ui.opacity }, 'Opacity');
    syncControls();
}

function setHide(on) {
    if (ui.hide === on) return;
    ui.hide = on;
    setView({ hideMakeup: on }, 'Before / after');
    syncControls();
}

function pickEnv(name) {
    if (!rouge || name === ui.env) return;
    const old = ui.env;
    ui.env = name;
    syncControls();
    setView({ env: name }, 'Lighting').then(() => {
        if (rouge.getView().env !== name) ui.env = old, syncControls();
    });
}

function stepEnv(d) {
    const i = ui.envs.indexOf(ui.env);
    pickEnv(ui.envs[(i + d + ui.envs.length) % ui.envs.length]);
    toast(`Lighting: ${ui.env === 'paper' ? 'paper lamp' : ui.env}`);
}

function setSun(deg) {
    ui.envRotation = deg;
    setView({ envRotation: deg }, 'Sun');
    syncControls();
}

function setPipeline(p) {
    ui.pipeline = p;
    setView({ pipeline: p }, 'Renderer');
    syncControls();
}

function zoomBy(f) {
    if (rouge) act(rouge.zoomAt(f, canvas.clientWidth / 2, canvas.clientHeight / 2), 'Zoom');
}

function orbitBy(yaw, pitch) {
    if (rouge) act(rouge.orbit(yaw, pitch), 'Turn');
}

function resetView() {
    const s = ui.start;
    ui.envRotation = 0;
    setView({ yaw: s.yaw ?? 0, pitch: s.pitch ?? 0, zoom: s.zoom ?? 1, pan: [0, 0], envRotation: 0 }, 'Reset');
    syncControls();
}

function undo(redo = false) {
    if (rouge) act(redo ? rouge.redo() : rouge.undo(), redo ? 'Redo' : 'Undo').then(refresh);
}

function download(blob, name) {
    const a = document.createElement('a');
    a.href = URL.createObjectURL(blob);
    a.download = name;
    document.body.append(a);
    a.click();
    a.remove();
    setTimeout(() => URL.revokeObjectURL(a.href), 10000);
}

const stamp = () => new Date().toISOString().slice(0, 19).replace(/[-:]/g, '').replace('T', '-');

async function screenshot() {
    if (!rouge) return;
    const blob = await act(rouge.render().then(() => rouge.toBlob()), 'Screenshot');
    if (blob) download(blob, `rouge-${stamp()}.png`), toast('Screenshot saved');
}

// ---- the look library (localStorage) ----

function readLooks() {
    try {
        const v = JSON.parse(localStorage.getItem(LOOKS_KEY) || '[]');
        return Array.isArray(v) ? v.filter((l) => l && typeof l.name === 'string' && typeof l.text === 'string') : [];
    } catch (e) {
        return [];
    }
}

function writeLooks(looks) {
    try {
        localStorage.setItem(LOOKS_KEY, JSON.stringify(looks));
        return true;
    } catch (e) {
        toast(`Looks cannot be kept in this browser: ${e.message}`, true);
        return false;
    }
}

function addLook(name, text) {
    const looks = readLooks().filter((l) => l.name !== name);
    looks.unshift({ name, text, saved: new Date().toISOString() });
    if (writeLooks(looks)) listLooks();
}

function listLooks() {
    const list = $('#looks'), looks = readLooks();
    list.replaceChildren();
    $('#looks-empty').hidden = looks.length > 0;
    for (const l of looks) {
        const li = document.createElement('li');
        const load = document.createElement('button');
        load.type = 'button';
        load.className = 'pill look-load';
        load.setAttribute('aria-label', `Load ${l.name}`);
        const name = document.createElement('span');
        name.textContent = l.name;
        const when = document.createElement('small');
        when.textContent = l.saved ? new Date(l.saved).toLocaleDateString(undefined, { month: 'short', day: 'numeric' }) : '';
        load.append(name, when);
        load.addEventListener('click', () => loadLook(l.text, l.name));
        const exp = iconButton('i-download', `Export ${l.name} as a .look file`, () =>
            download(new Blob([l.text], { type: 'text/plain' }), `${fileName(l.name)}.look`));
        const del = iconButton('i-trash', `Delete ${l.name}`, () => {
            if (!confirm(`Delete the look “${l.name}”?`)) return;
            writeLooks(readLooks().filter((x) => x.name !== l.name));
            listLooks();
        });
        li.append(load, exp, del);
        list.append(li);
    }
}

function iconButton(icon, label, onClick) {
    const b = document.createElement('button');
    b.type = 'button';
    b.className = 'icon';
    b.setAttribute('aria-label', label);
    b.title = label;
    b.innerHTML = `<svg aria-hidden="true"><use href="#${icon}"/></svg>`;
    b.addEventListener('click', onClick);
    return b;
}

const fileName = (s) => s.trim().replace(/[^\p{L}\p{N}_-]+/gu, '-').replace(/^-+|-+$/g, '') || 'look';

async function loadLook(text, name) {
    if (!rouge) return false;
    pending++;
    showState();
    try {
        await rouge.loadLook(text);
        toast(`Loaded “${name}”`);
        return true;
    } catch (e) {
        toast(`“${name}” is not a look rouge can load: ${e.message}`, true);
        return false;
    } finally {
        pending--;
        showState();
    }
}

async function saveLook(e) {
    e.preventDefault();
    if (!rouge) return;
    const field = $('#look-name');
    const name = field.value.trim() || `Look ${readLooks().length + 1}`;
    const text = await act(rouge.saveLook(), 'Save');
    if (text === undefined) return;
    addLook(name, text);
    field.value = '';
    toast(`Saved “${name}”`);
}

async function importLook(e) {
    const file = e.target.files?.[0];
    e.target.value = '';
    if (!file) return;
    const name = file.name.replace(/\.look$/i, '');
    const text = await file.text();
    if (await loadLook(text, name)) addLook(name, text);
}

async function exportLook() {
    if (!rouge) return;
    const text = await act(rouge.saveLook(), 'Export');
    if (text !== undefined) download(new Blob([text], { type: 'text/plain' }), `rouge-look-${stamp()}.look`);
}

// ---- panels ----

function openPanel(id) {
    for (const p of document.querySelectorAll('.panel')) {
        const open = p.id === id && p.hidden;
        p.hidden = !open;
        for (const b of document.querySelectorAll(`[aria-controls="${p.id}"]`)) b.setAttribute('aria-expanded', open);
    }
    if (id === 'panel-looks') listLooks();
    const panel = id && document.getElementById(id);
    // In the side column a panel may open below the fold (a sheet over the face is always in view).
    if (panel && !panel.hidden && getComputedStyle(panel).position === 'static') panel.scrollIntoView({ block: 'nearest' });
    syncControls();
}

const closePanels = () => openPanel(null);

// ---- the controls follow the model ----

function syncControls() {
    const p = ui.product;
    if (!p) return;
    root.classList.toggle('painting', ui.painting);
    root.classList.toggle('viewing', !ui.painting);
    pressed($('#mode-paint'), ui.painting);
    pressed($('#mode-view'), !ui.painting);
    pressed($('#eraser'), ui.eraser);
    pressed($('#smudge'), ui.tool === 'smudge');
    pressed($('#blend'), ui.tool === 'blend');
    pressed($('#mirror'), ui.mirror);
    pressed($('#region'), !ui.anyRegion && !!p.region && ui.tool === 'paint');
    $('#region').disabled = !p.region || ui.tool !== 'paint';  // smudge and blend keep to no region
    $('#region span').textContent = p.region ? `${pretty(p.region)} only` : 'Anywhere';
    pressed($('#before'), ui.hide);
    for (const b of document.querySelectorAll('.swatch')) {
        const on = b.dataset.name === p.name;
        b.setAttribute('aria-checked', on);
        b.tabIndex = on ? 0 : -1;
        b.classList.toggle('custom', on && isCustom());
        b.style.setProperty('--c', on && ui.edit.color ? ui.edit.color : hex(ui.products.find((x) => x.name === b.dataset.name).rgb));
    }
    const name = $('#product-name');
    name.replaceChildren(ui.tool !== 'paint' ? pretty(ui.tool) : ui.eraser ? 'Eraser' : pretty(p.name));
    const notes = ui.tool !== 'paint' ? [ui.tool === 'smudge' ? 'drags the makeup along' : 'softens its edges'] : [ui.eraser ? `for ${pretty(p.name).toLowerCase()}` : '', isCustom() ? 'edited' : '', p.region && !ui.anyRegion ? `stays on ${p.region}` : ''].filter(Boolean);
    if (notes.length) {
        const small = document.createElement('small');
        small.textContent = ` · ${notes.join(' · ')}`;
        name.append(small);
    }

    const size = sizeOf(), mm = rouge?.stats().faceHeightMm;
    $('#size').value = Math.round(sizeToSlider(size));
    $('#size-out').textContent = mm ? `${Math.round(size * mm)} mm` : `${Math.round(size * 100)}%`;
    $('#size').setAttribute('aria-valuetext', $('#size-out').textContent);
    $('#opacity').value = Math.round(opacityOf() * 100);
    $('#opacity-out').textContent = `${Math.round(opacityOf() * 100)}%`;

    $('#color').value = ui.edit.color || hex(p.rgb);
    const finish = ui.edit.finish === 'default' ? p.finish : ui.edit.finish;
    for (const b of document.querySelectorAll('#finish button')) b.setAttribute('aria-checked', b.dataset.finish === finish);
    const cov = ui.edit.coverage === 0 ? p.coverage : Math.max(0, ui.edit.coverage);
    $('#coverage').value = Math.round(cov * 100);
    $('#coverage-out').textContent = `${Math.round(cov * 100)}%`;
    $('#edit-reset').disabled = !isCustom();

    for (const b of document.querySelectorAll('#envs button')) b.setAttribute('aria-checked', b.dataset.env === ui.env);
    $('#sun').value = Math.round(ui.envRotation);
    $('#sun-out').textContent = `${Math.round(ui.envRotation)}°`;
    pressed($('#pipe-mobile'), ui.pipeline === 'mobile');
    pressed($('#pipe-reference'), ui.pipeline === 'reference');
}

// Undo / redo availability and the brush's size in mm come from the face.
function refresh() {
    if (!rouge) return;
    const s = rouge.stats();
    $('#undo').disabled = !s.canUndo;
    $('#redo').disabled = !s.canRedo;
    syncControls();
}

// ---- wiring ----

function wire() {
    $('#mode-paint').addEventListener('click', () => setPainting(true));
    $('#mode-view').addEventListener('click', () => setPainting(false));
    $('#undo').addEventListener('click', () => undo());
    $('#redo').addEventListener('click', () => undo(true));
    $('#eraser').addEventListener('click', () => toggle('eraser'));
    $('#smudge').addEventListener('click', () => setTool('smudge'));
    $('#blend').addEventListener('click', () => setTool('blend'));
    $('#mirror').addEventListener('click', () => toggle('mirror'));
    $('#region').addEventListener('click', () => toggle('anyRegion'));
    $('#shot').addEventListener('click', screenshot);
    $('#shot2').addEventListener('click', screenshot);
    $('#size').addEventListener('input', (e) => setSize(sliderToSize(+e.target.value)));
    $('#opacity').addEventListener('input', (e) => setOpacity(+e.target.value / 100));
    $('#sun').addEventListener('input', (e) => setSun(+e.target.value));
    $('#pipe-mobile').addEventListener('click', () => setPipeline('mobile'));
    $('#pipe-reference').addEventListener('click', () => setPipeline('reference'));
    $('#color').addEventListener('input', (e) => {
        ui.edit.color = e.target.value;
        setBrush({ color: ui.edit.color }, 'Colour');
        syncControls();
    });
    $('#coverage').addEventListener('input', (e) => {
        const c = +e.target.value / 100;
        ui.edit.coverage = c > 0 ? c : -1;  // 0 would mean "the preset's"
        setBrush({ coverage: ui.edit.coverage }, 'Coverage');
        syncControls();
    });
    $('#edit-reset').addEventListener('click', () => {
        ui.edit = { color: null, finish: 'default', coverage: 0 };
        setBrush({ ...ui.edit }, 'Product');
        syncControls();
    });
    for (const [btn, panel] of [['#open-light', 'panel-light'], ['#open-looks', 'panel-looks'],
                                ['#open-edit', 'panel-edit'], ['#open-help', 'panel-help']])
        $(btn).addEventListener('click', () => openPanel(panel));
    for (const b of document.querySelectorAll('.panel .close')) b.addEventListener('click', closePanels);
    $('#collapse').addEventListener('click', () => {
        const dock = $('#dock'), collapsed = dock.classList.toggle('collapsed');
        $('#collapse').setAttribute('aria-expanded', !collapsed);
        $('#collapse').setAttribute('aria-label', collapsed ? 'Show the makeup tray' : 'Hide the makeup tray');
    });
    $('#save-look').addEventListener('submit', saveLook);
    $('#import').addEventListener('change', importLook);
    $('#export').addEventListener('click', exportLook);
    $('#clear').addEventListener('click', () => {
        if (rouge) act(rouge.clear(), 'Clear').then(() => { refresh(); toast('Face cleared — Undo brings it back'); });
    });

    // Before / after: a tap toggles; a press held longer shows the bare face only while held.
    const before = $('#before');
    let downAt = 0, wasHidden = false;
    before.addEventListener('pointerdown', (e) => {
        if (e.button) return;
        downAt = performance.now();
        wasHidden = ui.hide;
        setHide(true);
    });
    const release = (e) => {
        if (downAt <= 0) return;
        const held = performance.now() - downAt > HOLD_MS;
        downAt = e.type === 'pointerup' ? -1 : 0;  // -1: the click that follows knows a pointer handled it
        setHide(held ? false : !wasHidden);
    };
    before.addEventListener('pointerup', release);
    before.addEventListener('pointercancel', release);
    before.addEventListener('pointerleave', release);
    before.addEventListener('click', () => {
        if (downAt === -1) { downAt = 0; return; }
        setHide(!ui.hide);  // keyboard or assistive technology
    });
    before.addEventListener('contextmenu', (e) => e.preventDefault());

    window.addEventListener('keydown', onKey);
    // Painting while the bare face is shown would paint blind: show the makeup again.
    canvas.addEventListener('pointerdown', () => { if (ui.hide && ui.painting) setHide(false); });
}

function onKey(e) {
    if (e.defaultPrevented || e.isComposing || !rouge) return;
    const t = e.target;
    if (t.matches?.('input[type="text"], input:not([type]), textarea, select')) {
        if (e.key === 'Escape') t.blur();
        return;
    }
    const ctrl = e.ctrlKey || e.metaKey;
    const key = e.key.length === 1 ? e.key.toLowerCase() : e.key;
    if (ctrl) {
        if (key === 'z') undo(e.shiftKey);
        else if (key === 'y') undo(true);
        else return;
        e.preventDefault();
        return;
    }
    if (e.altKey) return;
    // A focused slider or product list keeps its own arrow keys.
    if (e.key.startsWith('Arrow') && t.matches?.('input[type="range"], .swatch')) return;
    const bracket = e.code === 'BracketLeft' ? -1 : e.code === 'BracketRight' ? 1 : 0;
    if (bracket) {
        if (e.shiftKey) setOpacity(opacityOf() + bracket * 0.08);
        else setSize(sliderToSize(sizeToSlider(sizeOf()) + bracket * 80));
    } else if (/^[1-9]$/.test(key) && ui.products[+key - 1]) {
        pickProduct(ui.products[+key - 1]);
    } else {
        const actions = {
            p: () => setPainting(!ui.painting),
            e: () => toggle('eraser'),
            j: () => setTool(e.shiftKey ? 'blend' : 'smudge'),
            m: () => toggle('mirror'),
            k: () => { toggle('anyRegion'); toast(ui.anyRegion ? 'The brush paints anywhere' : 'The brush stays in its area'); },
            b: () => setHide(!ui.hide),
            c: () => openPanel('panel-edit'),
            g: () => stepEnv(e.shiftKey ? -1 : 1),
            r: () => setPipeline(ui.pipeline === 'mobile' ? 'reference' : 'mobile'),
            s: screenshot,
            '?': () => openPanel('panel-help'),
            h: () => openPanel('panel-help'),
            '0': resetView,
            '+': () => zoomBy(ZOOM_STEP),
            '=': () => zoomBy(ZOOM_STEP),
            '-': () => zoomBy(1 / ZOOM_STEP),
            ArrowLeft: () => orbitBy(ORBIT_STEP, 0),
            ArrowRight: () => orbitBy(-ORBIT_STEP, 0),
            ArrowUp: () => orbitBy(0, -ORBIT_STEP),
            ArrowDown: () => orbitBy(0, ORBIT_STEP),
            Delete: () => $('#clear').click(),
            Escape: closePanels,
        };
        const fn = actions[key];
        if (!fn) return;
        fn();
    }
    e.preventDefault();
}

// ---- start ----

async function main() {
    let opts;
    try {
        opts = parseQuery(location.search);
    } catch (e) {
        return showError(e.message);
    }
    root.classList.toggle('noui', !opts.ui);
    if (opts.size) {
        root.classList.add('sized');
        root.style.setProperty('--w', `${opts.size[0]}px`);
        root.style.setProperty('--h', `${opts.size[1]}px`);
    }
    if (!hasWebGL2()) return showError('this browser has no WebGL 2 (OpenGL ES 3.0): rouge cannot draw here');
    onProgress({ stage: 'module' });
    try {
        [ui.products, ui.envs] = await Promise.all([cosmetics(), environments()]);
        checkNames(opts, ui.envs, ui.products);
    } catch (e) {
        return showError(e instanceof RougeError ? e.message : `rouge_core.wasm could not be loaded: ${e.message}`);
    }
    ui.product = ui.products.find((p) => p.name === (opts.brush || 'lipstick_satin')) || ui.products[0];
    ui.painting = opts.mode === 'paint';
    ui.pipeline = opts.pipeline || 'mobile';
    ui.start = { yaw: opts.yaw, pitch: opts.pitch, zoom: opts.zoom };
    const view = { pipeline: ui.pipeline };
    for (const k of ['env', 'yaw', 'pitch', 'zoom']) if (opts[k] !== undefined) view[k] = opts[k];
    buildSwatches();
    buildEnvs();
    buildFinishes();
    wire();
    $('#dock').inert = true;
    $('#topbar').inert = true;
    syncControls();
    showSwatch();

    let r;
    try {
        r = await createRouge(canvas, {
            face: opts.face, view, brush: { cosmetic: ui.product.name }, painting: ui.painting,
            frameDelayMs: opts.slow, onProgress, onState,
        });
    } catch (e) {
        return showError(e.message);
    }
    const v = r.getView();
    ui.env = v.env, ui.envRotation = v.envRotation || 0;
    ui.anyRegion = r.getBrush().anyRegion;
    rouge = window.rouge = r;
    $('#dock').inert = false;
    $('#topbar').inert = false;
    $('#loader').hidden = true;
    showState();
}

$('#error-reload').addEventListener('click', () => location.reload());
main();
