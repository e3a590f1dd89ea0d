// Measures how the viewer copes with a long scene (not a test: prints only).
// usage: node tests/load_bench.mjs --u4d <u4d> --scene <scene dir> [--frames 60]
// Serves the scene with `u4d view --port 0`, opens it in headless Chromium,
// and prints: time to the first drawn frame, bytes fetched for it, the mean
// and worst time of a single-frame step (fetch + parse + draw), and the worst
// gap between animation frames while playing (a frozen page shows as a long
// gap).
import { spawn } from 'node:child_process';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

const here = dirname(fileURLToPath(import.meta.url));
const argv = process.argv.slice(2);
const arg = (k, d) => { const i = argv.indexOf(`--${k}`); return i >= 0 ? argv[i + 1] : d; };
const u4d = resolve(arg('u4d', join(here, '..', '..', 'build', 'apps', 'u4d')));
const steps = Number(arg('frames', '60'));
const server = spawn(u4d, ['view', resolve(arg('scene')), '--port', '0', '--viewer-dir', join(here, '..', 'dist')],
  { stdio: ['ignore', 'pipe', 'inherit'] });
const url = await new Promise((ok) => {
  let out = '';
  server.stdout.on('data', (d) => { out += d; const m = out.match(/http:\/\/127\.0\.0\.1:\d+\//); if (m) ok(m[0]); });
});
const browser = await chromium.launch({ executablePath: arg('chromium', '/usr/bin/chromium'), headless: true,
  args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--no-sandbox'] });
try {
  const page = await browser.newPage({ viewport: { width: 1200, height: 640 } });
  let bytes = 0;
  page.on('response', async (r) => { const b = await r.body().catch(() => null); if (b) bytes += b.length; });
  const t0 = Date.now();
  await page.goto(url);
  await page.evaluate(() => window.u4d.ready);
  const first = (Date.now() - t0) / 1000;
  const bytesFirst = bytes;
  const r = await page.evaluate(async (steps) => {
    const times = [];
    for (let i = 1; i <= steps; ++i) {
      const t = performance.now();
      await window.u4d.setFrame(i);
      times.push(performance.now() - t);
    }
    await window.u4d.setFrame(0);
    let last = performance.now(), worst = 0;
    window.u4d.setPlaying(true);
    const end = last + 3000;
    await new Promise((done) => {
      const f = (t) => { worst = Math.max(worst, t - last); last = t; if (t < end) requestAnimationFrame(f); else done(); };
      requestAnimationFrame(f);
    });
    window.u4d.setPlaying(false);
    const played = window.u4d.state.frameIdx;
    return { mean: times.reduce((a, b) => a + b, 0) / times.length, max: Math.max(...times), worst, played,
      n: window.u4d.state.index.frames.length, objects: window.u4d.state.index.objects.length };
  }, steps);
  console.log(`scene: ${r.n} frames, ${r.objects} objects`);
  console.log(`first frame drawn after ${first.toFixed(2)} s, ${(bytesFirst / 1e6).toFixed(2)} MB fetched`);
  console.log(`stepping ${steps} frames: mean ${r.mean.toFixed(0)} ms, worst ${r.max.toFixed(0)} ms per frame`);
  console.log(`playing 3 s: reached frame ${r.played}, worst gap between animation frames ${r.worst.toFixed(0)} ms`);
  console.log(`total fetched ${(bytes / 1e6).toFixed(1)} MB`);
} finally {
  await browser.close();
  server.kill();
}
