// Makes docs/web/phone.png, the README's phone-sized screenshot of the viewer page: Chromium's device
// emulation (390x844, DPR 2, touch), a lipstick painted across the lips and a mirrored blush, both through
// window.rouge.pointer, then the channels rounded to steps of 6 so that the PNG stays under 600 KB.
//
//   make web && python3 -m http.server -d build/web 8123 --bind 127.0.0.1 &
//   node docs/web/phone_shot.mjs http://127.0.0.1:8123/index.html docs/web/phone.png
//
// Needs puppeteer-core (tests/web/node_modules) and Debian's chromium; takes about a minute on SwiftShader.
import { createRequire } from 'module';
import fs from 'fs';

const require = createRequire(new URL('../../tests/web/', import.meta.url));
const puppeteer = require('puppeteer-core');
const [,, url = 'http://127.0.0.1:8123/index.html', out = 'docs/web/phone.png'] = process.argv;

const browser = await puppeteer.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium', headless: true,
    args: ['--no-sandbox', '--disable-gpu', '--no-first-run', '--disable-background-networking',
           '--enable-unsafe-swiftshader', '--use-angle=swiftshader'],
});
try {
    const page = await browser.newPage();
    await page.setViewport({ width: 390, height: 844, deviceScaleFactor: 2, isMobile: true, hasTouch: true });
    const settled = () => page.waitForFunction(() => /^(ready|error)/.test(document.documentElement.dataset.rougeState),
                                               { timeout: 300000, polling: 100 });
    await page.goto(url);
    await settled();
    const state = await page.evaluate(() => document.documentElement.dataset.rougeState);
    if (state !== 'ready') throw new Error(`the page says ${state}`);
    await page.evaluate(async () => {
        const r = window.rouge, c = document.querySelector('#face');
        const LIPS = 4, CHEEK = 1;  // rouge_pick regions
        const cx = c.clientWidth / 2, region = (x, y) => r.pick(x, y)?.region;
        const rows = [];
        for (let y = c.clientHeight * 0.3; y < c.clientHeight; y += 2) if (region(cx, y) === LIPS) rows.push(y);
        const y0 = Math.min(...rows), y1 = Math.max(...rows), ym = (y0 + y1) / 2;
        let x0 = cx, x1 = cx;
        while (region(x0 - 2, ym) === LIPS) x0 -= 2;
        while (region(x1 + 2, ym) === LIPS) x1 += 2;
        let id = 1, last;
        const stroke = (points) => {
            last = r.pointer({ type: 'down', id, x: points[0][0], y: points[0][1] });
            for (const [x, y] of points) last = r.pointer({ type: 'move', id, x, y });
            last = r.pointer({ type: 'up', id, x: points.at(-1)[0], y: points.at(-1)[1] });
            id++;
        };
        const pick = (name) => document.querySelector(`.swatch[data-name="${name}"]`).click();
        // Lipstick: strokes across the lips (the brush stays on them).
        pick('lipstick_satin');
        for (let y = y0 - 2; y <= y1 + 2; y += 4) stroke(Array.from({ length: 40 }, (_, i) => [x0 - 6 + i * (x1 - x0 + 12) / 39, y]));
        await last;
        // Blush, mirrored, at 45 %: three sweeps up the left cheek.
        const cheekY = y0 - (y1 - y0) * 2.2, xs = [];
        for (let x = 0; x < cx; x += 3) if (region(x, cheekY) === CHEEK) xs.push(x);
        const ccx = xs.length ? xs.reduce((a, b) => a + b) / xs.length : cx * 0.55;
        pick('blush');
        document.querySelector('#mirror').click();
        const opacity = document.querySelector('#opacity');
        opacity.value = 45;
        opacity.dispatchEvent(new Event('input'));
        for (let k = -1; k <= 1; k++)
            stroke(Array.from({ length: 26 }, (_, a) => [ccx - 25 + a * 2, cheekY + k * 10 + 10 - a * 0.8]));
        await last;
        document.querySelector('#mirror').click();
        pick('lipstick_satin');
        await r.render();
    });
    await new Promise((ok) => setTimeout(ok, 1500));  // the tray's scroll to the lipstick
    await settled();
    const shot = await page.screenshot({ encoding: 'base64' });
    const small = await page.evaluate(async (src) => {
        const img = new Image();
        img.src = src;
        await img.decode();
        const c = Object.assign(document.createElement('canvas'), { width: img.width, height: img.height });
        const g = c.getContext('2d');
        g.drawImage(img, 0, 0);
        const d = g.getImageData(0, 0, c.width, c.height);
        for (let i = 0; i < d.data.length; i++) if ((i & 3) !== 3) d.data[i] = Math.min(255, Math.round(d.data[i] / 6) * 6);
        g.putImageData(d, 0, 0);
        return c.toDataURL('image/png').split(',')[1];
    }, `data:image/png;base64,${shot}`);
    fs.writeFileSync(out, Buffer.from(small, 'base64'));
    console.log(`${out}: ${fs.statSync(out).size} bytes`);
} finally {
    await browser.close();
}
