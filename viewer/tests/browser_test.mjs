// The viewer in a real browser: Debian's Chromium, headless, driven by
// playwright-core. Generates a tiny synthetic capture (`u4d synth`), writes
// its ground-truth 4D scene (`u4d scene-from-gt`), serves it (`u4d view
// --port 0`), then checks what the page draws:
//  - the 3D canvas shows the objects in their instance colours (the
//    InstanceColor palette of scene.json) and changes between frames 0 and 5;
//  - the side picture shows the instance colours with the "instances"
//    overlay and changes when the overlay switches to "depth";
//  - one timeline mark per key-frame and the evaluation table are present;
//  - `u4d export-viewer` writes a folder with the bundle and the scene.
// Screenshots go to --screenshots (default: the work dir). Exit codes: 0 pass,
// 1 fail, 77 skipped (no Chromium), as ctest's SKIP_RETURN_CODE expects.
//
// usage: node tests/browser_test.mjs --u4d <u4d binary> [--work <dir>]
//          [--screenshots <dir>] [--chromium /usr/bin/chromium] [--keep]
import { spawn, spawnSync } from 'node:child_process';
import { existsSync, mkdirSync, rmSync, readFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const args = Object.fromEntries(process.argv.slice(2).reduce((acc, a, i, all) => {
  if (a.startsWith('--')) acc.push([a.slice(2), all[i + 1] && !all[i + 1].startsWith('--') ? all[i + 1] : true]);
  return acc;
}, []));
const u4d = resolve(args.u4d || join(here, '..', '..', 'build', 'apps', 'u4d'));
const chromiumPath = args.chromium || process.env.U4D_CHROMIUM || '/usr/bin/chromium';
const work = resolve(args.work || join(tmpdir(), `u4d_viewer_test_${process.pid}`));
const shots = resolve(args.screenshots || join(work, 'screenshots'));
const viewerDir = resolve(here, '..', 'dist');

let failures = 0;
const lap = (what) => console.log(`  [${((Date.now() - t0) / 1000).toFixed(1)} s] ${what}`);
function check(ok, what) {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
  if (!ok) failures += 1;
}
function run(cmd, argv) {
  const r = spawnSync(cmd, argv, { encoding: 'utf8' });
  if (r.status !== 0) throw new Error(`${cmd} ${argv.join(' ')} failed (${r.status}):\n${r.stdout}\n${r.stderr}`);
  return r.stdout;
}

if (!existsSync(chromiumPath)) {
  console.log(`SKIP: no Chromium at ${chromiumPath} (scripts/setup.sh installs it)`);
  process.exit(77);
}
let chromium;
try {
  ({ chromium } = await import('playwright-core'));
} catch (e) {
  console.log('SKIP: playwright-core is not installed (run `npm ci` in viewer/)');
  process.exit(77);
}
if (!existsSync(join(viewerDir, 'viewer.js'))) {
  console.log(`FAIL: the viewer is not built (${viewerDir}); run \`ninja viewer\``);
  process.exit(1);
}

rmSync(work, { recursive: true, force: true });
mkdirSync(shots, { recursive: true });
const t0 = Date.now();
// 8 frames so that frame 5 exists and people have moved; 2 small views.
run(u4d, ['synth', '--preset', 'handshake', '-o', join(work, 'capture'), '--frames', '8',
  '--views', '2', '--width', '240', '--height', '136', '--degrade', 'none']);
run(u4d, ['scene-from-gt', join(work, 'capture'), '-o', join(work, 'scene'), '--keyframe-interval', '4']);
const index = JSON.parse(readFileSync(join(work, 'scene', 'scene.json'), 'utf8'));
console.log(`scene written in ${((Date.now() - t0) / 1000).toFixed(1)} s`);

// u4d view on a free port; the address is the first line it prints.
const server = spawn(u4d, ['view', join(work, 'scene'), '--port', '0', '--viewer-dir', viewerDir],
  { stdio: ['ignore', 'pipe', 'inherit'] });
const url = await new Promise((ok, fail) => {
  let out = '';
  const timer = setTimeout(() => fail(new Error(`u4d view printed no address: ${out}`)), 10000);
  server.stdout.on('data', (d) => {
    out += d;
    const m = out.match(/http:\/\/127\.0\.0\.1:\d+\//);
    if (m) { clearTimeout(timer); ok(m[0]); }
  });
  server.on('exit', (code) => fail(new Error(`u4d view exited (${code}): ${out}`)));
});
console.log(`u4d view serves ${url}`);

const browser = await chromium.launch({
  executablePath: chromiumPath,
  headless: true,
  // Software WebGL: CI machines have no GPU.
  args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist', '--no-sandbox'],
});
try {
  const page = await browser.newPage({ viewport: { width: 1200, height: 640 } });
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  await page.goto(url);
  await page.evaluate(() => window.u4d.ready);
  lap('page loaded');

  // Pixels of the 3D canvas or the side picture, kept in the page (copying
  // megabytes of RGBA through the protocol is slow); the checks below run
  // there too and return counts.
  const snap = (id, name) => page.evaluate(([id, name]) => {
    if (id === 'canvas3d') window.u4d.render();
    const c = document.getElementById(id);
    const tmp = document.createElement('canvas');
    tmp.width = c.width; tmp.height = c.height;
    const ctx = tmp.getContext('2d');
    ctx.drawImage(c, 0, 0);
    (window.snaps ||= {})[name] = ctx.getImageData(0, 0, c.width, c.height).data;
  }, [id, name]);
  // Pixels within 6 levels (rendering rounding) of an RGB colour.
  const countColour = (name, rgb) => page.evaluate(([name, rgb]) => {
    const d = window.snaps[name];
    let n = 0;
    for (let i = 0; i < d.length; i += 4) {
      if (Math.abs(d[i] - rgb[0]) <= 6 && Math.abs(d[i + 1] - rgb[1]) <= 6 &&
          Math.abs(d[i + 2] - rgb[2]) <= 6) n += 1;
    }
    return n;
  }, [name, rgb]);
  // Pixels whose colour differs by more than 30 levels (sum over RGB).
  const changed = (a, b) => page.evaluate(([a, b]) => {
    const x = window.snaps[a], y = window.snaps[b];
    if (x.length !== y.length) return x.length / 4;
    let n = 0;
    for (let i = 0; i < x.length; i += 4) {
      if (Math.abs(x[i] - y[i]) + Math.abs(x[i + 1] - y[i + 1]) + Math.abs(x[i + 2] - y[i + 2]) > 30) n += 1;
    }
    return n;
  }, [a, b]);
  await page.evaluate(() => window.u4d.setLit(false));
  await page.evaluate(() => window.u4d.setFrame(0));
  await snap('canvas3d', 'f0');
  lap('frame 0 drawn');
  // Each person covers thousands of canvas pixels at this zoom; 100 pixels of
  // its exact colour is a loose floor that an uncoloured or missing mesh fails.
  for (const o of index.objects) {
    const n = await countColour('f0', o.color);
    check(n >= 100, `3D canvas, frame 0: object ${o.id} colour rgb(${o.color}) covers ${n} px (>= 100)`);
  }
  await page.screenshot({ path: join(shots, 'viewer_frame0.png') });

  await page.evaluate(() => window.u4d.setFrame(5));
  await snap('canvas3d', 'f5');
  lap('frame 5 drawn');
  const label = await page.textContent('#frame-label');
  check(label.includes('frame 5'), `timeline label after stepping: "${label}"`);
  // The people move between frames 0 and 5 (0.2 s at 25 fps): their pixels
  // shift, so some hundred canvas pixels change colour.
  const nChanged = await changed('f0', 'f5');
  check(nChanged >= 100, `3D canvas changes between frames 0 and 5: ${nChanged} px (>= 100)`);

  // Side picture: instance overlay at full opacity shows the instance colours,
  // then the depth overlay changes it.
  await page.evaluate(() => { window.u4d.state.alpha = 1; return window.u4d.setOverlay('instances'); });
  await snap('picture', 'inst');
  for (const o of index.objects) {
    const n = await countColour('inst', o.color);
    check(n >= 50, `side picture, instances overlay: object ${o.id} covers ${n} px (>= 50)`);
  }
  await page.evaluate(() => window.u4d.setOverlay('depth'));
  await snap('picture', 'depth');
  const nDepth = await changed('inst', 'depth');
  check(nDepth >= 200, `side picture changes from instances to depth: ${nDepth} px (>= 200)`);
  check(await countColour('depth', index.objects[0].color) < (await countColour('inst', index.objects[0].color)) / 4,
    'depth overlay no longer shows the instance colour');
  await page.evaluate(() => { window.u4d.state.alpha = 0.6; return window.u4d.setOverlay('depth'); });
  await page.evaluate(() => window.u4d.setLit(true));
  await page.screenshot({ path: join(shots, 'viewer_depth.png') });
  await page.evaluate(() => window.u4d.setOverlay('flow'));
  await page.evaluate(() => window.u4d.setColourMode('keyframe'));
  await page.screenshot({ path: join(shots, 'viewer_flow_keyframe_colours.png') });

  const marks = await page.locator('#keyframe-marks .kf').count();
  check(marks === index.keyframes.length, `timeline shows ${marks} key-frame marks (${index.keyframes.length} key-frames)`);
  const evalRows = await page.locator('#eval table tr').count();
  check(evalRows > 5, `evaluation table has ${evalRows} rows`);

  // Play for a moment: the frame advances without errors.
  await page.evaluate(() => window.u4d.setPlaying(true));
  await page.waitForTimeout(600);
  await page.evaluate(() => window.u4d.setPlaying(false));
  const drawn = await page.evaluate(() => window.u4d.state.drawn);
  check(drawn >= 4, `playing draws frames (${drawn} drawn so far)`);
  check(errors.length === 0, `no page errors${errors.length ? ': ' + errors.join(' | ') : ''}`);

  // Without WebGL the page says so instead of staying blank.
  const noGl = await chromium.launch({
    executablePath: chromiumPath, headless: true,
    args: ['--disable-webgl', '--disable-3d-apis', '--no-sandbox'],
  });
  try {
    const bare = await noGl.newPage();
    await bare.goto(url);
    await bare.waitForSelector('#fatal:not([hidden])', { timeout: 10000 }).catch(() => {});
    const fatal = await bare.$eval('#fatal', (e) => (e.hidden ? '' : e.textContent));
    check(fatal.includes('needs WebGL'), `without WebGL the page says so ('${fatal.slice(0, 50)}')`);
  } finally {
    await noGl.close();
  }
} finally {
  await browser.close();
  server.kill();
}

// export-viewer: a folder with the bundle and the viewer's part of the scene.
const exported = join(work, 'export');
run(u4d, ['export-viewer', join(work, 'scene'), '-o', exported, '--viewer-dir', viewerDir]);
check(existsSync(join(exported, 'index.html')) && existsSync(join(exported, 'viewer.js')),
  'export-viewer wrote the bundle');
check(existsSync(join(exported, 'scene', 'scene.json')) &&
      existsSync(join(exported, 'scene', 'meshes', '01', '000000.ply')),
  'export-viewer wrote the scene');
check(!existsSync(join(exported, 'scene', 'depth')), 'export-viewer left out the raw depth maps');

console.log(`${failures ? 'FAILED' : 'passed'} in ${((Date.now() - t0) / 1000).toFixed(1)} s; screenshots in ${shots}`);
if (!args.keep && failures === 0) rmSync(join(work, 'capture'), { recursive: true, force: true });
process.exit(failures ? 1 : 0);
