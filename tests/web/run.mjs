// The browser tests: build/web served on loopback, Debian's chromium (headless, WebGL 2 on SwiftShader)
// driven over the DevTools protocol by puppeteer-core, real touch and pen events (Input.dispatch*).
// Prints `ok - ` / `FAIL - ` / `skip - ` lines for tests/run.sh. SwiftShader draws a frame in about a second
// at these sizes, so the canvases are small and the events few.
// Usage: node tests/web/run.mjs BUILD_DIR [--bench]   (--bench: print the load rows for tools/bench.sh)
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import http from 'node:http';
import os from 'node:os';
import path from 'node:path';
import puppeteer from 'puppeteer-core';

const build = process.argv[2] || 'build';
const benchOnly = process.argv.includes('--bench');
const web = path.join(build, 'web');
const SIZE = 224;                 // canvas, CSS px (device pixel ratio 1)
const READY_MS = 180000;
const out = process.env.RS_TEST_OUT || path.join(build, 'test-out');
fs.mkdirSync(out, { recursive: true });

let failures = 0;
const ok = (name) => console.log(`ok - web: ${name}`);
const fail = (name, why) => { failures++; console.log(`FAIL - web: ${name}: ${why}`); };
const check = (name, cond, detail) => (cond ? ok(`${name} (${detail})`) : fail(name, detail));

// ---- a static server with a few test routes ----
const TYPES = { '.html': 'text/html', '.js': 'text/javascript', '.wasm': 'application/wasm', '.css': 'text/css' };
const face = fs.readFileSync(path.join(web, 'face.rsf'));
const corrupt = Buffer.from(face);
for (let i = 200000; i < 200064; i++) corrupt[i] ^= 0x5a;  // inside the first LOD level's compressed block
const server = http.createServer((req, res) => {
    const url = new URL(req.url, 'http://x');
    if (url.pathname === '/test/corrupt.rsf') return res.end(corrupt);
    if (url.pathname === '/test/slow.rsf') {  // ~1.5 MB/s in 64 KiB pieces: a phone's connection
        res.writeHead(200, { 'content-length': face.length });
        let at = 0;
        const next = () => {
            if (at >= face.length) return res.end();
            res.write(face.subarray(at, at + 65536));
            at += 65536;
            setTimeout(next, 40);
        };
        return next();
    }
    const file = path.join(web, path.normalize(decodeURIComponent(url.pathname)).replace(/^(\.\.[/\\])+/, ''));
    fs.readFile(file, (err, data) => {
        if (err) { res.writeHead(404); return res.end('not found'); }
        res.writeHead(200, { 'content-type': TYPES[path.extname(file)] || 'application/octet-stream' });
        res.end(data);
    });
});
await new Promise((r) => server.listen(0, '127.0.0.1', r));
const base = `http://127.0.0.1:${server.address().port}`;

const browser = await puppeteer.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    headless: true,
    args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
           '--disable-component-update', '--disable-sync', '--enable-unsafe-swiftshader', '--use-angle=swiftshader',
           '--disable-renderer-backgrounding', '--disable-background-timer-throttling'],
    protocolTimeout: READY_MS,
});

async function open(query, { noWebGL2 = false } = {}) {
    const page = await browser.newPage();
    await page.setViewport({ width: SIZE + 16, height: SIZE + 16, deviceScaleFactor: 1, hasTouch: true });
    page.on('pageerror', (e) => console.log(`# page error: ${e.message}`));
    if (noWebGL2)  // a browser without WebGL 2: getContext('webgl2') gives null, as on old phones
        await page.evaluateOnNewDocument(() => {
            const get = HTMLCanvasElement.prototype.getContext;
            HTMLCanvasElement.prototype.getContext = function (t, ...a) { return t === 'webgl2' ? null : get.call(this, t, ...a); };
        });
    const cdp = await page.createCDPSession();
    await cdp.send('Emulation.setTouchEmulationEnabled', { enabled: true, maxTouchPoints: 5 });
    await page.goto(`${base}/index.html?ui=0&size=${SIZE}x${SIZE}&${query}`);
    const state = await settle(page);
    return { page, cdp, state };
}

async function settle(page) {
    await page.waitForFunction(() => {
        const s = document.documentElement.dataset.rougeState || '';
        return s === 'ready' || s.startsWith('error');
    }, { timeout: READY_MS, polling: 100 });
    return page.evaluate(() => document.documentElement.dataset.rougeState);
}

const pixels = (page) => page.evaluate(() => {
    const p = window.rouge.readPixels();
    return { width: p.width, height: p.height, data: Array.from(p.data) };
});

// What is on screen: the canvas as Chromium composited it, decoded in the page.
async function screen(page) {
    const png = await page.screenshot({ clip: { x: 0, y: 0, width: SIZE, height: SIZE }, encoding: 'base64' });
    return decode(page, png);
}

const decode = (page, b64) => page.evaluate(async (b64) => {
    const img = await createImageBitmap(await (await fetch(`data:image/png;base64,${b64}`)).blob());
    const c = new OffscreenCanvas(img.width, img.height);
    const g = c.getContext('2d');
    g.drawImage(img, 0, 0);
    return { width: img.width, height: img.height, data: Array.from(g.getImageData(0, 0, img.width, img.height).data) };
}, b64);

// Writes an RGBA image (as pixels() gives them) to a PNG in the test output folder, for a person to look at.
async function savePng(page, img, name) {
    const b64 = await page.evaluate(async (img) => {
        const c = new OffscreenCanvas(img.width, img.height);
        c.getContext('2d').putImageData(new ImageData(new Uint8ClampedArray(img.data), img.width, img.height), 0, 0);
        const bytes = new Uint8Array(await (await c.convertToBlob({ type: 'image/png' })).arrayBuffer());
        let s = '';
        for (const b of bytes) s += String.fromCharCode(b);
        return btoa(s);
    }, img);
    fs.writeFileSync(path.join(out, name), Buffer.from(b64, 'base64'));
}

function psnr(a, b) {
    let se = 0, n = 0;
    for (let i = 0; i < a.data.length; i += 4)
        for (let c = 0; c < 3; c++, n++) se += (a.data[i + c] - b.data[i + c]) ** 2;
    return 10 * Math.log10(255 * 255 / Math.max(se / n, 1e-9));
}

const changed = (a, b, i) => Math.abs(a.data[i] - b.data[i]) + Math.abs(a.data[i + 1] - b.data[i + 1]) +
                             Math.abs(a.data[i + 2] - b.data[i + 2]) > 12;

async function touchStroke(cdp, pts, force = 1) {
    await cdp.send('Input.dispatchTouchEvent', { type: 'touchStart', touchPoints: [{ x: pts[0][0], y: pts[0][1], id: 1, force }] });
    for (const [x, y] of pts.slice(1)) await cdp.send('Input.dispatchTouchEvent', { type: 'touchMove', touchPoints: [{ x, y, id: 1, force }] });
    await cdp.send('Input.dispatchTouchEvent', { type: 'touchEnd', touchPoints: [] });
}

async function penStroke(cdp, pts, force) {
    const ev = (type, [x, y], buttons) => cdp.send('Input.dispatchMouseEvent', {
        type, x, y, button: 'left', buttons, clickCount: 1, pointerType: 'pen', force, tiltX: 20, tiltY: 0 });
    await ev('mousePressed', pts[0], 1);
    for (const p of pts.slice(1)) await ev('mouseMoved', p, 1);
    await ev('mouseReleased', pts[pts.length - 1], 0);
}

const line = (x0, y0, x1, y1, n) => Array.from({ length: n + 1 }, (_, i) => [x0 + (x1 - x0) * i / n, y0 + (y1 - y0) * i / n]);

// The lips as the face's own region view shows them: pixels of the region colour found most often under
// picks of region 4 (a grid over the lower face; one pick alone may land on a blended edge pixel).
async function lipsMask(page) {
    return page.evaluate(async (size) => {
        const r = window.rouge, hits = [];
        for (let y = Math.round(size * 0.5); y < size; y += 3)
            for (let x = Math.round(size * 0.2); x < size * 0.8; x += 3)
                if (r.pick(x, y)?.region === 4) hits.push([x, y]);
        if (!hits.length) return null;
        await r.setView({ mode: 'regions' });
        await r.render();
        const p = r.readPixels();
        await r.setView({ mode: 'full' });
        await r.render();
        const votes = new Map();
        for (const [x, y] of hits) {
            const k = (y * p.width + x) * 4, key = (p.data[k] << 16) | (p.data[k + 1] << 8) | p.data[k + 2];
            votes.set(key, (votes.get(key) || 0) + 1);
        }
        const key = [...votes].sort((a, b) => b[1] - a[1])[0][0];
        const col = [key >> 16, (key >> 8) & 255, key & 255], mask = [];
        for (let i = 0; i < p.width * p.height; i++)
            mask.push(Math.abs(p.data[i * 4] - col[0]) + Math.abs(p.data[i * 4 + 1] - col[1]) +
                      Math.abs(p.data[i * 4 + 2] - col[2]) < 6 ? 1 : 0);
        const seed = hits[Math.floor(hits.length / 2)];
        return { seed, mask, width: p.width, height: p.height, regions: { width: p.width, height: p.height, data: Array.from(p.data) } };
    }, SIZE);
}

function dilate(m, w, h, rad) {
    const o = new Array(m.length).fill(0);
    for (let y = 0; y < h; y++)
        for (let x = 0; x < w; x++) {
            if (!m[y * w + x]) continue;
            for (let dy = -rad; dy <= rad; dy++)
                for (let dx = -rad; dx <= rad; dx++) {
                    const X = x + dx, Y = y + dy;
                    if (X >= 0 && Y >= 0 && X < w && Y < h) o[Y * w + X] = 1;
                }
        }
    return o;
}

async function run(name, fn) {
    if (process.env.WEB_ONLY && !name.includes(process.env.WEB_ONLY) && name !== 'page gets ready') return;  // debugging
    const t0 = Date.now();
    try {
        await fn();
    } catch (e) {
        fail(name, String(e.message || e).split('\n')[0]);
    }
    console.log(`# ${name}: ${((Date.now() - t0) / 1000).toFixed(1)} s`);
}

// ---- the tests ----

if (benchOnly) {  // tools/bench.sh: bytes and time until the first LOD level is drawn, over a throttled stream
    const { page, state } = await open('face=test/slow.rsf');
    const s = await page.evaluate(() => window.rouge?.stats());
    if (state !== 'ready' || !s) console.log(`web_first_lod error ${state}`);
    else console.log(`web_first_lod ${s.load.firstDrawBytes} ${s.load.firstDrawMs.toFixed(0)} ${s.load.totalBytes} ${s.load.totalMs.toFixed(0)}`);
    await browser.close();
    server.close();
    process.exit(0);
}

// One page in paint mode serves the picture, the lipstick, the pressure and the gesture tests.
// It streams the face at a phone's speed, so the same load shows the coarsest level drawn early.
const view = 'face=test/slow.rsf&env=daylight&yaw=20&pitch=5&pipeline=mobile&mode=paint&brush=lipstick_satin';
let main;
await run('page gets ready', async () => {
    main = await open(view);
    check('page gets ready', main.state === 'ready', `data-rouge-state=${main.state}`);
});
if (main?.state === 'ready') {
    const { page, cdp } = main;

    await run('the coarsest level is drawn before the face has arrived', async () => {
        const s = await page.evaluate(() => window.rouge.stats());
        check('the coarsest level is drawn before the face has arrived', s.load.firstDrawBytes < s.load.totalBytes / 2,
              `first frame after ${s.load.firstDrawBytes} of ${s.load.totalBytes} bytes (${s.load.firstDrawMs.toFixed(0)} ms)`);
    });

    await run('the page shows what rouge render shows', async () => {
        const png = path.join(out, 'web_native.png');
        execFileSync(path.join(build, 'rouge'), ['render', '--size', `${SIZE}x${SIZE}`, '--env', 'daylight', '--yaw', '20',
            '--pitch', '5', '--pipeline', 'mobile', '-o', png], { stdio: 'pipe' });
        const native = await decode(page, fs.readFileSync(png).toString('base64'));
        const shown = await screen(page);
        const db = psnr(shown, native);
        check('the page shows what rouge render shows', db >= 32, `PSNR ${db.toFixed(1)} dB >= 32 against the native render`);
    });

    let lips = null, lipsView = null;  // the lips' pixels and the view they were found in
    await run('a one-finger lipstick stroke paints the lips and nothing else', async () => {
        lips = await lipsMask(page);
        lipsView = await page.evaluate(() => { const v = window.rouge.getView(); return { yaw: v.yaw, pitch: v.pitch, zoom: v.zoom, pan: v.pan }; });
        if (!lips) throw new Error('no lips pixel found by picking');
        const { mask, width: w } = lips;
        // The lips' widest row: the stroke runs along it, beyond both corners of the mouth.
        let best = -1, bestN = 0;
        for (let y = 0; y < lips.height; y++) {
            let n = 0;
            for (let x = 0; x < w; x++) n += mask[y * w + x];
            if (n > bestN) bestN = n, best = y;
        }
        let x0 = w, x1 = 0;
        for (let x = 0; x < w; x++) if (mask[best * w + x]) x0 = Math.min(x0, x), x1 = Math.max(x1, x);
        const before = await pixels(page);
        await touchStroke(cdp, line(x0 - 12, best, x1 + 12, best, 16));
        await settle(page);
        const after = await pixels(page);
        const near = dilate(mask, w, lips.height, 2);
        let inside = 0, outside = 0;
        for (let i = 0; i < mask.length; i++) if (changed(before, after, i * 4)) near[i] ? inside++ : outside++;
        const spill = outside / Math.max(1, inside + outside);
        const diff = { width: w, height: lips.height, data: [] };
        for (let i = 0; i < mask.length; i++) {
            const c = changed(before, after, i * 4);
            diff.data.push(c && !near[i] ? 255 : 0, c && near[i] ? 255 : 0, mask[i] ? 160 : 0, 255);
        }
        await savePng(page, before, 'web_lips_before.png');
        await savePng(page, after, 'web_lips_after.png');
        await savePng(page, diff, 'web_lips_diff.png');
        await savePng(page, lips.regions, 'web_lips_regions.png');  // red: changed off the lips, green: on, blue: lips
        check('a one-finger lipstick stroke paints the lips and nothing else', inside >= 40 && spill <= 0.005,
              `${inside} lip pixels changed, ${outside} elsewhere (${(100 * spill).toFixed(2)} % <= 0.5 %)`);
        await page.evaluate(() => window.rouge.undo());
        await settle(page);
    });

    await run('pen pressure 0.2 and 1.0 give visibly different strokes', async () => {
        if (!lips) throw new Error('needs the lips from the stroke test');
        await page.evaluate(() => window.rouge.setBrush({ pressure: 'linear' }));
        const y = lips.seed[1], x = lips.seed[0];
        const pts = line(x - 10, y, x + 10, y, 8);
        const before = await pixels(page);
        const strength = async (force) => {
            await penStroke(cdp, pts, force);
            await settle(page);
            const after = await pixels(page);
            let sum = 0;
            for (let i = 0; i < after.data.length; i += 4)
                sum += Math.abs(after.data[i] - before.data[i]) + Math.abs(after.data[i + 1] - before.data[i + 1]) +
                       Math.abs(after.data[i + 2] - before.data[i + 2]);
            await page.evaluate(() => window.rouge.undo());
            await settle(page);
            return sum;
        };
        const light = await strength(0.2), firm = await strength(1.0);
        check('pen pressure 0.2 and 1.0 give visibly different strokes', light > 0 && firm > 2 * light,
              `colour change ${light} at 0.2, ${firm} at 1.0`);
        await page.evaluate(() => window.rouge.setBrush({ pressure: 'floor' }));
    });

    await run('a pinch zooms and a two-finger move pans', async () => {
        const v0 = await page.evaluate(() => window.rouge.getView());
        const c = SIZE / 2;
        // Each gesture's events are sent at once (a frame costs seconds on SwiftShader; they queue and apply
        // in order all the same); a close-up costs more per frame, so the pinch stays modest.
        const two = (type, d, dx) => cdp.send('Input.dispatchTouchEvent', { type, touchPoints: type === 'touchEnd' ? [] : [
            { x: c - d + dx, y: c, id: 1 }, { x: c + d + dx, y: c, id: 2 }] });
        const gesture = async (events) => {
            await Promise.all(events.map(([type, d, dx]) => two(type, d, dx)));
            await settle(page);
            return page.evaluate(() => window.rouge.getView());
        };
        const pinch = [['touchStart', 20, 0]];
        for (let d = 23; d <= 35; d += 3) pinch.push(['touchMove', d, 0]);
        const v1 = await gesture([...pinch, ['touchEnd', 35, 0]]);
        const move = [['touchStart', 30, 0]];
        for (let dx = 5; dx <= 40; dx += 5) move.push(['touchMove', 30, dx]);
        const v2 = await gesture([...move, ['touchEnd', 30, 40]]);
        check('a pinch zooms', Math.abs(v1.zoom / v0.zoom - 1.75) < 0.1,
              `zoom ${v0.zoom.toFixed(2)} -> ${v1.zoom.toFixed(2)} for fingers 40 -> 70 px apart (1.75x)`);
        check('a two-finger move pans', Math.abs(v2.pan[0] - v1.pan[0]) > 0.05 && Math.abs(v2.zoom / v1.zoom - 1) < 0.05,
              `pan x ${v1.pan[0].toFixed(3)} -> ${v2.pan[0].toFixed(3)}, zoom kept ${v2.zoom.toFixed(2)}`);
        check('two fingers never paint', (await page.evaluate(() => window.rouge.stats().lookStamps)) === 0, 'no stamps');
    });

    await run('two fingers twisting turn the head', async () => {
        const v0 = await page.evaluate(() => window.rouge.getView());
        const c = SIZE / 2, r = 30, ev = [];
        const at = (deg) => [{ x: c + r * Math.cos(deg * Math.PI / 180), y: c + r * Math.sin(deg * Math.PI / 180), id: 1 },
                             { x: c - r * Math.cos(deg * Math.PI / 180), y: c - r * Math.sin(deg * Math.PI / 180), id: 2 }];
        ev.push(cdp.send('Input.dispatchTouchEvent', { type: 'touchStart', touchPoints: at(0) }));
        for (let d = 5; d <= 30; d += 5) ev.push(cdp.send('Input.dispatchTouchEvent', { type: 'touchMove', touchPoints: at(d) }));
        ev.push(cdp.send('Input.dispatchTouchEvent', { type: 'touchEnd', touchPoints: [] }));
        await Promise.all(ev);
        await settle(page);
        const v1 = await page.evaluate(() => window.rouge.getView());
        check('two fingers twisting turn the head', Math.abs(v1.yaw - v0.yaw - 30) < 3,
              `yaw ${v0.yaw.toFixed(1)} -> ${v1.yaw.toFixed(1)} for a 30 deg twist`);
    });

    await run('while a pen is down, touches are ignored (palm rejection)', async () => {
        await page.evaluate(() => window.rouge.setBrush({ cosmetic: 'blush' }));
        const before = await page.evaluate(() => window.rouge.stats());
        const c = SIZE / 2, pen = (type, x, buttons) => cdp.send('Input.dispatchMouseEvent', {
            type, x, y: c, button: 'left', buttons, clickCount: 1, pointerType: 'pen', force: 0.8 });
        await pen('mousePressed', c - 30, 1);
        await cdp.send('Input.dispatchTouchEvent', { type: 'touchStart', touchPoints: [{ x: c, y: c + 60, id: 5 }] });
        for (let i = 1; i <= 4; i++) {
            await cdp.send('Input.dispatchTouchEvent', { type: 'touchMove', touchPoints: [{ x: c + 8 * i, y: c + 60, id: 5 }] });
            await pen('mouseMoved', c - 30 + 12 * i, 1);
        }
        await cdp.send('Input.dispatchTouchEvent', { type: 'touchEnd', touchPoints: [] });
        await pen('mouseReleased', c + 18, 0);
        await settle(page);
        const s = await page.evaluate(() => window.rouge.stats());
        check('while a pen is down, touches are ignored (palm rejection)',
              s.events - before.events === 6 && s.lookStamps > before.lookStamps,
              `${s.events - before.events} events reached rouge (the pen's 6; the palm's 6 ignored), ` +
              `${s.lookStamps - before.lookStamps} stamps`);
    });

    await run('a stroke made while frames are slow keeps every event', async () => {
        await page.evaluate(() => window.rouge.setBrush({ cosmetic: 'blush' }));
        await page.evaluate(() => { window.rouge.options.frameDelayMs = 700; });  // what ?slow=700 sets
        const before = await page.evaluate(() => window.rouge.stats());
        const c = SIZE / 2;
        const pts = line(c - 40, c - 10, c + 30, c + 5, 30);
        // Sent without waiting for each: they pile up while a frame stalls the page, and Chromium coalesces
        // touch moves that wait (the page must take them back with getCoalescedEvents).
        const sent = [cdp.send('Input.dispatchTouchEvent', { type: 'touchStart', touchPoints: [{ x: pts[0][0], y: pts[0][1], id: 1 }] })];
        for (const [x, y] of pts.slice(1)) sent.push(cdp.send('Input.dispatchTouchEvent', { type: 'touchMove', touchPoints: [{ x, y, id: 1 }] }));
        sent.push(cdp.send('Input.dispatchTouchEvent', { type: 'touchEnd', touchPoints: [] }));
        await Promise.all(sent);
        await settle(page);
        const s = await page.evaluate(() => { window.rouge.options.frameDelayMs = 0; return window.rouge.stats(); });
        const n = pts.length + 1, got = s.eventsApplied - before.eventsApplied, frames = s.frames - before.frames;
        check('a stroke made while frames are slow keeps every event',
              s.events - before.events === n && got === n && s.lookStamps > before.lookStamps && !s.inStroke,
              `${got} of ${n} events applied over ${frames} frames of 700 ms, ${s.lookStamps - before.lookStamps} stamps`);
    });

    await run('the smudge tool drags the lipstick off the lips', async () => {
        // The gesture tests in between turned and zoomed the head and cleared the face: back to the view the
        // lips were found in (or find them, run alone), and a lipstick along the lips' widest row.
        if (lipsView) await page.evaluate((v) => window.rouge.setView(v), lipsView), await settle(page);
        else lips = await lipsMask(page);
        if (!lips) throw new Error('no lips pixel found by picking');
        let best = -1, bestN = 0;
        for (let y = 0; y < lips.height; y++) {
            let k = 0;
            for (let x = 0; x < lips.width; x++) k += lips.mask[y * lips.width + x];
            if (k > bestN) bestN = k, best = y;
        }
        let x0 = lips.width, x1 = 0;
        for (let x = 0; x < lips.width; x++) if (lips.mask[best * lips.width + x]) x0 = Math.min(x0, x), x1 = Math.max(x1, x);
        await page.evaluate(() => window.rouge.setBrush({ cosmetic: 'lipstick_satin' }));
        await touchStroke(cdp, line(x0, best, x1, best, 16));
        await settle(page);
        const bad = await page.evaluate(() => window.rouge.setBrush({ tool: 'rub' }).then(() => 'accepted', (e) => e.message));
        await page.evaluate(() => window.rouge.setBrush({ tool: 'smudge', size: 0.05 }));
        const { mask, width: w, height: h } = lips;
        // From the middle of the lips straight down, past the lower lip onto the chin.
        let sx = 0, sy = 0, n = 0;
        for (let y = 0; y < h; y++) for (let x = 0; x < w; x++) if (mask[y * w + x]) sx += x, sy += y, n++;
        const cx = Math.round(sx / n), cy = Math.round(sy / n);
        let bottom = cy;
        for (let y = cy; y < h; y++) if (mask[y * w + cx]) bottom = y;
        const before = await pixels(page);
        await touchStroke(cdp, line(cx, cy, cx, Math.min(h - 2, bottom + 18), 12));
        await settle(page);
        const after = await pixels(page);
        await page.evaluate(() => window.rouge.setBrush({ tool: 'paint' }));
        const near = dilate(mask, w, h, 2);
        let outside = 0;
        for (let i = 0; i < mask.length; i++) if (!near[i] && changed(before, after, i * 4)) outside++;
        await savePng(page, after, 'web_smudge.png');
        check('the smudge tool drags the lipstick off the lips', outside >= 15 && /brush\.tool "rub"/.test(bad),
              `${outside} pixels below the lips changed; tool "rub": ${bad}`);
    });
    await page.close();
}

for (const [name, query, opts, want] of [
    ['a missing face URL ends in a clear error', 'face=test/missing.rsf', {}, /^error: .*missing\.rsf.*404/],
    ['a corrupt face ends in a clear error', 'face=test/corrupt.rsf', {}, /^error: .*corrupt\.rsf/],
    ['a page without WebGL 2 ends in a clear error', '', { noWebGL2: true }, /^error: .*WebGL 2/],
    ['a bad query value ends in a clear error', 'yaw=sideways', {}, /^error: .*yaw/],
]) {
    await run(name, async () => {
        const { page, state } = await open(query, opts);
        const shown = await page.evaluate(() => document.body.innerText);
        const msg = state.replace(/^error: /, '');
        check(name, want.test(state) && shown.includes(msg), `${state}`);
        await page.close();
    });
}

await browser.close();
server.close();
process.exit(failures ? 1 : 0);
