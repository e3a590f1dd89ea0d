// The U4D web viewer: plays a 4D scene written by `u4d run` (or
// `u4d scene-from-gt`). The scene is read by relative URLs from `scene/`
// next to this page (or from ?scene=<url>); its index scene.json (written by
// src/u4d/io/scene_index.cc) lists the frames, views, objects, key-frames,
// segments and path templates. Meshes are streamed per frame (one PLY per
// object and frame, cached, a few frames prefetched), so a long scene never
// needs one large download. docs/viewer.md describes the page.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { PLYLoader } from 'three/examples/jsm/loaders/PLYLoader.js';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';

const params = new URLSearchParams(location.search);
const sceneBase = (params.get('scene') || 'scene/').replace(/\/?$/, '/');
const kPrefetch = 4;        // frames loaded ahead of the current one
const kCacheFrames = 48;    // mesh frames kept in memory
const kFrustumDepth = 0.35; // metres drawn of each camera's frustum
const kTrackTail = 10;      // frames of history drawn per track

const $ = (id) => document.getElementById(id);
const pad = (n, w) => String(n).padStart(w, '0');

// ---------------------------------------------------------------- state
const state = {
  index: null, calibration: null, evalJson: null, keyframes: [],
  frameIdx: 0, playing: false, colourMode: params.get('colour') || 'instance',
  lit: params.get('lit') !== '0', view: 0, overlay: null, alpha: 0.7,
  drawn: 0, // frames drawn (for tests)
};

function fileUrl(key, vars) {
  let t = state.index.files[key];
  for (const [k, v] of Object.entries(vars)) t = t.replace(`{${k}}`, v);
  return sceneBase + t;
}

async function fetchJson(url, optional = false) {
  const r = await fetch(url);
  if (!r.ok) {
    if (optional) return null;
    throw new Error(`${url}: HTTP ${r.status}`);
  }
  return r.json();
}

function setStatus(text) { $('status').textContent = text; }

// ---------------------------------------------------------------- three.js
const canvas = $('canvas3d');

// Without WebGL the page says so instead of staying blank.
function webglAvailable() {
  try {
    const probe = document.createElement('canvas');
    return !!(probe.getContext('webgl2') || probe.getContext('webgl'));
  } catch (e) {
    return false;
  }
}

function showFatal(text) {
  const box = $('fatal');
  box.textContent = text;
  box.hidden = false;
  setStatus(text);
}

let renderer;
try {
  if (!webglAvailable()) throw new Error('no WebGL context could be created');
  renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
} catch (e) {
  showFatal('The U4D viewer needs WebGL, which this browser does not provide (' + e.message +
            '). Enable hardware acceleration or WebGL in the browser settings, or try another ' +
            'browser.');
  throw e;
}
renderer.setPixelRatio(window.devicePixelRatio);
const scene3 = new THREE.Scene();
scene3.background = new THREE.Color(0x1e1f22);
const camera3 = new THREE.PerspectiveCamera(45, 1, 0.01, 200);
const controls = new OrbitControls(camera3, canvas);
controls.addEventListener('change', () => render());
scene3.add(new THREE.HemisphereLight(0xffffff, 0x404050, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 1.4);
scene3.add(sun);
const groups = {
  meshes: new THREE.Group(), cameras: new THREE.Group(), poses: new THREE.Group(),
};
Object.values(groups).forEach((g) => scene3.add(g));
const litMaterial = new THREE.MeshLambertMaterial({ vertexColors: true, side: THREE.DoubleSide });
const flatMaterial = new THREE.MeshBasicMaterial({ vertexColors: true, side: THREE.DoubleSide });

function resize() {
  const w = canvas.clientWidth, h = canvas.clientHeight;
  if (canvas.width !== Math.floor(w * renderer.getPixelRatio()) ||
      canvas.height !== Math.floor(h * renderer.getPixelRatio())) {
    renderer.setSize(w, h, false);
    camera3.aspect = w / Math.max(h, 1);
    camera3.updateProjectionMatrix();
  }
}

function render() {
  resize();
  sun.position.copy(camera3.position);
  renderer.render(scene3, camera3);
}
window.addEventListener('resize', () => render());

// ---------------------------------------------------------------- cameras
function mat3(m) { // nested or flat row-major -> flat array of 9
  return Array.isArray(m[0]) ? m.flat() : m;
}

function cameraAt(cam, frame) {
  if (cam.per_frame) return cam.per_frame[Math.min(frame, cam.per_frame.length - 1)];
  return cam;
}

// World position of pixel (u, v) at depth z, and the camera centre.
function unproject(c, u, v, z) {
  const K = mat3(c.K), R = mat3(c.R), t = c.t;
  const y = (v - K[5]) / K[4];
  const x = (u - K[2] - K[1] * y) / K[0];
  const p = [x * z - t[0], y * z - t[1], z - t[2]];
  return new THREE.Vector3(
    R[0] * p[0] + R[3] * p[1] + R[6] * p[2],
    R[1] * p[0] + R[4] * p[1] + R[7] * p[2],
    R[2] * p[0] + R[5] * p[1] + R[8] * p[2]);
}

function buildCameras(frame) {
  groups.cameras.clear();
  const cams = state.calibration ? state.calibration.cameras : [];
  cams.forEach((cam, i) => {
    const c = cameraAt(cam, frame);
    const w = c.width ?? cam.width, h = c.height ?? cam.height;
    const o = unproject(c, 0, 0, 0);
    const corners = [[-0.5, -0.5], [w - 0.5, -0.5], [w - 0.5, h - 0.5], [-0.5, h - 0.5]]
      .map(([u, v]) => unproject(c, u, v, kFrustumDepth));
    const pts = [];
    corners.forEach((p, k) => { pts.push(o, p, p, corners[(k + 1) % 4]); });
    // A tick on the top edge marks "up" in the image.
    const top = corners[0].clone().lerp(corners[1], 0.5);
    pts.push(top, top.clone().lerp(o, -0.15));
    const geom = new THREE.BufferGeometry().setFromPoints(pts);
    const selected = i === state.view;
    const line = new THREE.LineSegments(geom, new THREE.LineBasicMaterial({
      color: selected ? 0xffd54f : 0x9aa0a6 }));
    line.userData.view = cam.view;
    groups.cameras.add(line);
  });
}

// Up = minus the mean image-y axis of the cameras; target = the point closest
// to all optical axes (least squares); eye = behind and above the first camera.
function frameTheScene() {
  const cams = state.calibration ? state.calibration.cameras.map((c) => cameraAt(c, 0)) : [];
  if (cams.length === 0) { camera3.position.set(4, 3, 4); controls.target.set(0, 1, 0); return; }
  const up = new THREE.Vector3();
  const A = new THREE.Matrix3().set(0, 0, 0, 0, 0, 0, 0, 0, 0);
  const a = [0, 0, 0, 0, 0, 0, 0, 0, 0], b = [0, 0, 0];
  const centres = [];
  for (const c of cams) {
    const R = mat3(c.R);
    up.add(new THREE.Vector3(-R[3], -R[4], -R[5]));
    const d = new THREE.Vector3(R[6], R[7], R[8]).normalize();
    const o = unproject(c, 0, 0, 0);
    centres.push(o);
    const dd = [d.x, d.y, d.z], oo = [o.x, o.y, o.z];
    for (let r = 0; r < 3; ++r) {
      for (let s = 0; s < 3; ++s) {
        const m = (r === s ? 1 : 0) - dd[r] * dd[s];
        a[r * 3 + s] += m;
        b[r] += m * oo[s];
      }
    }
  }
  up.normalize();
  A.set(...a);
  let target;
  if (cams.length >= 2 && Math.abs(A.determinant()) > 1e-6) {
    target = new THREE.Vector3(...b).applyMatrix3(A.clone().invert());
  } else {
    target = centres[0].clone().add(unproject(cams[0], mat3(cams[0].K)[2], mat3(cams[0].K)[5], 3).sub(centres[0]));
  }
  camera3.up.copy(up);
  // A floor grid when the world is y-up (synthetic captures: the floor is y = 0).
  if (Math.abs(up.y) > 0.9) {
    const grid = new THREE.GridHelper(12, 24, 0x555a60, 0x34373c);
    grid.name = 'floor';
    scene3.add(grid);
  }
  const eye = centres[0].clone().sub(target).multiplyScalar(1.25).add(target)
    .add(up.clone().multiplyScalar(1.0));
  camera3.position.copy(eye);
  controls.target.copy(target);
  controls.update();
}

// ---------------------------------------------------------------- meshes
const plyLoader = new PLYLoader();
plyLoader.setCustomPropertyNameMapping({ label: ['label'] });
const meshCache = new Map(); // "frame" -> Promise<[{id, geometry}]>

function objectColour(id) {
  const o = state.index.objects.find((x) => x.id === id);
  const rgb = o ? o.color : [200, 200, 200];
  return new THREE.Color().setRGB(rgb[0] / 255, rgb[1] / 255, rgb[2] / 255, THREE.SRGBColorSpace);
}

async function loadPly(url, id) {
  const r = await fetch(url);
  if (!r.ok) return null; // an object absent at this frame
  const g = plyLoader.parse(await r.arrayBuffer());
  const n = g.attributes.position.count;
  const inst = new Float32Array(n * 3);
  const label = g.attributes.label;
  for (let i = 0; i < n; ++i) {
    const c = objectColour(label ? label.getX(i) : id);
    inst[3 * i] = c.r; inst[3 * i + 1] = c.g; inst[3 * i + 2] = c.b;
  }
  g.userData.instanceColour = new THREE.BufferAttribute(inst, 3);
  g.userData.keyframeColour = g.attributes.color || g.userData.instanceColour;
  if (!g.attributes.normal) g.computeVertexNormals();
  return { id, geometry: g };
}

function loadFrame(fi) {
  const frame = state.index.frames[fi];
  if (meshCache.has(frame)) return meshCache.get(frame);
  const p = Promise.all(state.index.objects.map((o) =>
    loadPly(fileUrl('mesh', { object: pad(o.id, 2), frame: pad(frame, 6) }), o.id)))
    .then((list) => list.filter(Boolean));
  meshCache.set(frame, p);
  while (meshCache.size > kCacheFrames) { // evict the oldest entry
    const [key, old] = meshCache.entries().next().value;
    meshCache.delete(key);
    old.then((list) => list.forEach((m) => m.geometry.dispose()));
  }
  return p;
}

// Segment glTF with one morph target per frame (fusion/gltf.h), used when
// the scene has no per-frame PLY meshes.
const gltfCache = new Map();
function loadSegmentGlb(path) {
  if (!gltfCache.has(path)) gltfCache.set(path, new GLTFLoader().loadAsync(sceneBase + path));
  return gltfCache.get(path);
}

async function showGlbFrame(frame) {
  const seg = state.index.segments.find((s) => frame >= s.first && frame <= s.last);
  groups.meshes.clear();
  if (!seg) return;
  for (const [id, path] of Object.entries(seg.glb || {})) {
    const gltf = await loadSegmentGlb(path);
    gltf.scene.traverse((m) => {
      if (!m.isMesh) return;
      if (m.morphTargetInfluences) {
        const k = frame - seg.first;
        m.morphTargetInfluences.fill(0);
        if (k > 0 && k - 1 < m.morphTargetInfluences.length) m.morphTargetInfluences[k - 1] = 1;
        if (m.morphTargetInfluences.length === seg.last - seg.first + 1) {
          m.morphTargetInfluences.fill(0); m.morphTargetInfluences[k] = 1;
        }
      }
      if (state.colourMode === 'instance') {
        m.material = (state.lit ? litMaterial : flatMaterial).clone();
        m.material.vertexColors = false;
        m.material.color = objectColour(Number(id));
      }
    });
    groups.meshes.add(gltf.scene);
  }
}

let shownMeshes = [];
function showMeshes(list) {
  groups.meshes.clear();
  shownMeshes = list;
  const material = state.lit ? litMaterial : flatMaterial;
  for (const { geometry } of list) {
    geometry.setAttribute('color', state.colourMode === 'instance'
      ? geometry.userData.instanceColour : geometry.userData.keyframeColour);
    groups.meshes.add(new THREE.Mesh(geometry, material));
  }
}

// ---------------------------------------------------------------- poses
async function showPoses(frame) {
  groups.poses.clear();
  if (!state.index.has_poses3d) return;
  const j = await fetchJson(fileUrl('poses3d', { frame: pad(frame, 6) }), true);
  if (!j) return;
  const bones = state.index.skeleton ? state.index.skeleton.bones : [];
  for (const person of j.people || []) {
    const pts = [];
    for (const [a, b] of bones) {
      const ja = person.joints[a], jb = person.joints[b];
      if (!ja || !jb || ja[3] <= 0 || jb[3] <= 0) continue;
      pts.push(new THREE.Vector3(ja[0], ja[1], ja[2]), new THREE.Vector3(jb[0], jb[1], jb[2]));
    }
    const colour = person.id >= 1 ? objectColour(person.id).offsetHSL(0, 0, 0.25) : new THREE.Color(0xffffff);
    const line = new THREE.LineSegments(new THREE.BufferGeometry().setFromPoints(pts),
      new THREE.LineBasicMaterial({ color: colour, depthTest: false }));
    line.renderOrder = 1;
    groups.poses.add(line);
  }
}

// ---------------------------------------------------------------- pictures
const pictureCanvas = $('picture');
const pictureCtx = pictureCanvas.getContext('2d', { willReadFrequently: true });
const imageCache = new Map();
const trackCache = new Map();

function loadImage(url) {
  if (!imageCache.has(url)) {
    imageCache.set(url, new Promise((resolve) => {
      const im = new Image();
      im.onload = () => resolve(im);
      im.onerror = () => resolve(null);
      im.src = url;
    }));
    if (imageCache.size > 200) imageCache.delete(imageCache.keys().next().value);
  }
  return imageCache.get(url);
}

function pictureUrl(kind, fi) {
  const v = state.index.views[state.view];
  return fileUrl('picture', { kind, view: v.name, frame: pad(state.index.frames[fi], 6) });
}

async function loadTracks(view) {
  if (!state.index.has_tracks) return null;
  if (!trackCache.has(view)) trackCache.set(view, fetchJson(fileUrl('tracks', { view }), true));
  return trackCache.get(view);
}

async function drawPicture(fi) {
  const v = state.index.views[state.view];
  if (!v) return;
  const kinds = state.index.pictures || [];
  const base = kinds.includes('image') ? await loadImage(pictureUrl('image', fi)) : null;
  // Forward flow (t -> t+1) does not exist for the last frame.
  const lastFrame = fi === state.index.frames.length - 1;
  const over = state.overlay && state.overlay !== 'image' && !(state.overlay === 'flow' && lastFrame)
    ? await loadImage(pictureUrl(state.overlay, fi)) : null;
  const w = (base || over || {}).naturalWidth || v.width;
  const h = (base || over || {}).naturalHeight || v.height;
  pictureCanvas.width = w; pictureCanvas.height = h;
  pictureCtx.fillStyle = '#000';
  pictureCtx.fillRect(0, 0, w, h);
  if (base) pictureCtx.drawImage(base, 0, 0, w, h);
  if (over) {
    pictureCtx.globalAlpha = base ? state.alpha : 1;
    pictureCtx.drawImage(over, 0, 0, w, h);
    pictureCtx.globalAlpha = 1;
  }
  if ($('show-tracks').checked) {
    const tracks = await loadTracks(v.name);
    if (tracks) drawTracks(tracks, state.index.frames[fi], w / v.width, h / v.height);
  }
}

// tracks/<view>.json: {"tracks": [{"id", "instance", "points": [[frame, x, y], ...]}]}
function drawTracks(tracks, frame, sx, sy) {
  pictureCtx.lineWidth = 1;
  for (const t of tracks.tracks || []) {
    const pts = t.points.filter((p) => p[0] <= frame && p[0] > frame - kTrackTail);
    if (pts.length === 0 || pts[pts.length - 1][0] !== frame) continue;
    const c = objectColour(t.instance || 0).getHexString(THREE.SRGBColorSpace);
    pictureCtx.strokeStyle = pictureCtx.fillStyle = `#${c}`;
    pictureCtx.beginPath();
    pts.forEach((p, k) => {
      const x = (p[1] + 0.5) * sx - 0.5, y = (p[2] + 0.5) * sy - 0.5;
      if (k === 0) pictureCtx.moveTo(x, y); else pictureCtx.lineTo(x, y);
    });
    pictureCtx.stroke();
    const last = pts[pts.length - 1];
    pictureCtx.fillRect((last[1] + 0.5) * sx - 2, (last[2] + 0.5) * sy - 2, 3, 3);
  }
}

const legends = {
  image: 'input image (downscaled)',
  instances: 'instance masks, colour = object',
  depth: 'depth: near = red ... far = blue (Turbo), black = unknown',
  flow: 'forward flow t -> t+1: hue = direction, saturation = speed (Middlebury)',
};
function drawLegend() {
  const parts = [legends[state.overlay] || ''];
  const swatches = state.index.objects.map((o) =>
    `<span class="swatch" style="background:rgb(${o.color.join(',')})"></span>${o.class} ${o.id}`);
  $('legend').innerHTML = parts.join('') + '<br>' + swatches.join('');
}

// ---------------------------------------------------------------- eval table
function renderEval(j) {
  const rows = [];
  const fmt = (v) => (typeof v === 'number' ? (Number.isInteger(v) ? String(v) : v.toFixed(4)) : String(v));
  const flat = (prefix, v, out) => {
    if (v !== null && typeof v === 'object' && !Array.isArray(v)) {
      for (const [k, x] of Object.entries(v)) flat(prefix ? `${prefix}.${k}` : k, x, out);
    } else if (!Array.isArray(v)) out.push([prefix, v]);
  };
  for (const [section, v] of Object.entries(j)) {
    if (section === 'format' || section === 'source') continue;
    const out = [];
    flat('', v, out);
    if (out.length === 0) continue;
    rows.push(`<tr><th class="section" colspan="2">${section}</th></tr>`);
    for (const [k, x] of out) {
      rows.push(`<tr><td>${k || section}</td><td class="num">${x === null ? 'n/a' : fmt(x)}</td></tr>`);
    }
  }
  $('eval').innerHTML = `<h3>evaluation${j.source ? ` of ${j.source}` : ''}</h3><table>${rows.join('')}</table>`;
}

// ---------------------------------------------------------------- timeline
function keyframeOf(frame) {
  return state.keyframes.find((k) => k.members.includes(frame));
}

function updateTimelineLabel() {
  const frame = state.index.frames[state.frameIdx];
  const kf = keyframeOf(frame);
  const mark = kf && kf.frame === frame ? ' [key-frame]' : kf ? ` (key ${kf.frame})` : '';
  $('frame-label').textContent = `frame ${frame} / ${state.index.frames.at(-1)}${mark}`;
  $('scrub').value = state.frameIdx;
}

function drawKeyframeMarks() {
  const n = state.index.frames.length;
  const marks = state.keyframes.map((k) => {
    const i = state.index.frames.indexOf(k.frame);
    const x = n > 1 ? (100 * i) / (n - 1) : 0;
    return `<div class="kf" style="left:calc(${x}% - 1px)" title="key-frame ${k.frame}"></div>`;
  });
  $('keyframe-marks').innerHTML = marks.join('');
}

// ---------------------------------------------------------------- frame
let frameToken = 0;
async function setFrame(fi) {
  const n = state.index.frames.length;
  fi = Math.max(0, Math.min(n - 1, fi));
  state.frameIdx = fi;
  const token = ++frameToken;
  const frame = state.index.frames[fi];
  updateTimelineLabel();
  const jobs = [drawPicture(fi), showPoses(frame)];
  if (state.index.has_meshes) {
    jobs.push(loadFrame(fi).then((list) => { if (token === frameToken) showMeshes(list); }));
    for (let k = 1; k <= kPrefetch && fi + k < n; ++k) loadFrame(fi + k);
  } else if (state.index.segments.length) {
    jobs.push(showGlbFrame(frame));
  }
  if (state.calibration && state.calibration.cameras.some((c) => c.per_frame)) buildCameras(frame);
  await Promise.all(jobs);
  if (token === frameToken) {
    render();
    state.drawn += 1;
  }
}

function refresh() { return setFrame(state.frameIdx); }

let lastTick = 0;
function tick(t) {
  if (state.playing) {
    const dt = 1000 / (state.index.fps || 25);
    if (t - lastTick >= dt && !tick.busy) {
      lastTick = t;
      tick.busy = true;
      const next = (state.frameIdx + 1) % state.index.frames.length;
      setFrame(next).finally(() => { tick.busy = false; });
    }
  }
  requestAnimationFrame(tick);
}

function setPlaying(on) {
  state.playing = on;
  $('play').innerHTML = on ? '&#10074;&#10074;' : '&#9654;';
}

// ---------------------------------------------------------------- UI
function bindUi() {
  const idx = state.index;
  $('title').textContent = `U4D viewer - ${idx.name}`;
  $('scrub').max = idx.frames.length - 1;
  $('scrub').addEventListener('input', (e) => setFrame(Number(e.target.value)));
  $('play').addEventListener('click', () => setPlaying(!state.playing));
  $('step-back').addEventListener('click', () => { setPlaying(false); setFrame(state.frameIdx - 1); });
  $('step-fwd').addEventListener('click', () => { setPlaying(false); setFrame(state.frameIdx + 1); });
  window.addEventListener('keydown', (e) => {
    if (e.target.tagName === 'SELECT' || e.target.tagName === 'INPUT' && e.target.type !== 'range') return;
    if (e.key === ' ') { setPlaying(!state.playing); e.preventDefault(); }
    if (e.key === 'ArrowRight') { setPlaying(false); setFrame(state.frameIdx + 1); e.preventDefault(); }
    if (e.key === 'ArrowLeft') { setPlaying(false); setFrame(state.frameIdx - 1); e.preventDefault(); }
  });
  const viewSel = $('view-select');
  idx.views.forEach((v, i) => viewSel.add(new Option(`${v.name} (${v.width}x${v.height})`, i)));
  viewSel.addEventListener('change', () => {
    state.view = Number(viewSel.value);
    buildCameras(idx.frames[state.frameIdx]);
    drawPicture(state.frameIdx).then(render);
  });
  const overSel = $('overlay-select');
  for (const k of idx.pictures) overSel.add(new Option(k, k));
  state.overlay = params.get('overlay') || (idx.pictures.includes('instances') ? 'instances' : idx.pictures[0]);
  overSel.value = state.overlay;
  overSel.addEventListener('change', () => { state.overlay = overSel.value; drawLegend(); drawPicture(state.frameIdx); });
  $('overlay-alpha').value = state.alpha;
  $('overlay-alpha').addEventListener('input', (e) => { state.alpha = Number(e.target.value); drawPicture(state.frameIdx); });
  $('show-tracks').addEventListener('change', () => drawPicture(state.frameIdx));
  const colourSel = $('colour-mode');
  colourSel.value = state.colourMode;
  colourSel.addEventListener('change', () => { state.colourMode = colourSel.value; refresh(); });
  $('lit').checked = state.lit;
  $('lit').addEventListener('change', (e) => { state.lit = e.target.checked; refresh(); });
  for (const [box, group] of [['show-meshes', 'meshes'], ['show-cameras', 'cameras'], ['show-poses', 'poses']]) {
    $(box).addEventListener('change', (e) => { groups[group].visible = e.target.checked; render(); });
  }
  drawKeyframeMarks();
  drawLegend();
}

// ---------------------------------------------------------------- start
async function start() {
  setStatus('loading scene.json ...');
  state.index = await fetchJson(sceneBase + 'scene.json');
  state.index.segments = state.index.segments || [];
  state.index.pictures = state.index.pictures || [];
  state.keyframes = state.index.keyframes || [];
  state.calibration = await fetchJson(fileUrl('calibration', {}), true);
  bindUi();
  frameTheScene();
  buildCameras(state.index.frames[0]);
  if (state.index.has_eval) {
    state.evalJson = await fetchJson(fileUrl('eval', {}), true);
    if (state.evalJson) renderEval(state.evalJson);
  }
  await setFrame(Number(params.get('frame') || 0));
  setStatus(`${state.index.frames.length} frames, ${state.index.views.length} views, ` +
            `${state.index.objects.length} objects`);
  requestAnimationFrame(tick);
}

// Hooks for the browser test and for scripting from the console.
const ready = start().catch((e) => { setStatus(`error: ${e.message}`); console.error(e); throw e; });
window.u4d = {
  ready, state, setFrame, setPlaying, refresh, render,
  setOverlay: (k) => { state.overlay = k; $('overlay-select').value = k; drawLegend(); return drawPicture(state.frameIdx); },
  setColourMode: (m) => { state.colourMode = m; $('colour-mode').value = m; return refresh(); },
  setLit: (on) => { state.lit = on; $('lit').checked = on; return refresh(); },
};
