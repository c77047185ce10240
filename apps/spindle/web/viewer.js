// spindle view's page: draws the scene the program describes (GET /scene) with the poses
// of the newest frame (GET /frame, binary, polled one request at a time so a slow page
// skips frames rather than queueing them), shows the program's numbers (GET /stats), and
// sends the user's actions as one-line commands (POST /command). The frame layout is
// written down in apps/spindle/view_frames.hpp.
'use strict';

const FRAME_MAGIC = 0x46565053;
const FLAG_PAUSED = 1, FLAG_INTERPOLATED = 2, FLAG_REPLAY = 4, FLAG_SLOW = 8;
const BODY_FLOATS = 8, CONTACT_FLOATS = 7, HEADER_BYTES = 40;

// What the page has done, for people and for tests (tests read it with chromium --dump-dom
// from the #state element).
const state = {
  frames: 0, sceneVersion: 0, sceneBodies: 0, drawnBodies: 0, asleep: 0, moved: 0, shots: 0,
  commandsRefused: 0, lastError: '', flags: 0, replay: false, test: '', testDone: false, shotGrew: false,
};  // moved: the furthest a body has gone from where it was first drawn
window.spindleView = state;

const canvas = document.getElementById('view');
const renderer = new THREE.WebGLRenderer({ canvas, antialias: true });
renderer.setPixelRatio(window.devicePixelRatio || 1);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x1d2026);
scene.add(new THREE.HemisphereLight(0xdde6ff, 0x30343c, 0.75));
const sun = new THREE.DirectionalLight(0xffffff, 0.7);
sun.position.set(0.4, 1, 0.3);
scene.add(sun);
const camera = new THREE.PerspectiveCamera(50, 1, 0.05, 2000);

// ---- orbit camera: yaw and pitch about a target, distance by the wheel ----
const orbit = { target: new THREE.Vector3(0, 1, 0), distance: 20, yaw: 0.7, pitch: 0.35 };
function placeCamera() {
  orbit.pitch = Math.max(-1.5, Math.min(1.5, orbit.pitch));
  orbit.distance = Math.max(0.5, Math.min(1500, orbit.distance));
  const c = Math.cos(orbit.pitch);
  camera.position.set(orbit.target.x + orbit.distance * c * Math.sin(orbit.yaw),
                      orbit.target.y + orbit.distance * Math.sin(orbit.pitch),
                      orbit.target.z + orbit.distance * c * Math.cos(orbit.yaw));
  camera.lookAt(orbit.target);
}
function resize() {
  const w = window.innerWidth, h = window.innerHeight;
  renderer.setSize(w, h, false);
  camera.aspect = w / Math.max(1, h);
  camera.updateProjectionMatrix();
}
window.addEventListener('resize', resize);
resize();
placeCamera();

// ---- geometry from the scene description ----
function capsuleGeometry(radius, halfHeight) {
  const profile = [];
  const n = 10;
  for (let i = 0; i <= n; i++) {  // top cap, pole to equator
    const a = (Math.PI / 2) * (i / n);
    profile.push(new THREE.Vector2(radius * Math.sin(a), halfHeight + radius * Math.cos(a)));
  }
  for (let i = 0; i <= n; i++) {  // bottom cap, equator to pole
    const a = (Math.PI / 2) * (i / n);
    profile.push(new THREE.Vector2(radius * Math.cos(a), -halfHeight - radius * Math.sin(a)));
  }
  return new THREE.LatheBufferGeometry(profile, 20);
}

// The hull's faces: every triangle of its points with all the others on one side (the
// program sends the points, not the faces; hulls are small).
function hullGeometry(points) {
  const p = points.map((v) => new THREE.Vector3(v[0], v[1], v[2]));
  let size = 0;
  for (const v of p) size = Math.max(size, v.length());
  const eps = 1e-6 * Math.max(1, size);
  const positions = [];
  const ab = new THREE.Vector3(), ac = new THREE.Vector3(), n = new THREE.Vector3(), d = new THREE.Vector3();
  for (let i = 0; i < p.length; i++) {
    for (let j = i + 1; j < p.length; j++) {
      for (let k = j + 1; k < p.length; k++) {
        ab.subVectors(p[j], p[i]);
        ac.subVectors(p[k], p[i]);
        n.crossVectors(ab, ac);
        if (n.lengthSq() < eps * eps) continue;
        let above = 0, below = 0;
        for (let m = 0; m < p.length && !(above && below); m++) {
          const s = n.dot(d.subVectors(p[m], p[i]));
          if (s > eps) above++;
          else if (s < -eps) below++;
        }
        if (above && below) continue;
        const tri = above ? [p[i], p[k], p[j]] : [p[i], p[j], p[k]];  // outward: the others behind
        for (const v of tri) positions.push(v.x, v.y, v.z);
      }
    }
  }
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.Float32BufferAttribute(positions, 3));
  g.computeVertexNormals();
  return g;
}

function meshGeometry(points, indices) {
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.Float32BufferAttribute([].concat(...points), 3));
  g.setIndex(indices);
  g.computeVertexNormals();
  return g;
}

function planeObject(shape, material) {
  const group = new THREE.Group();
  const ground = new THREE.Mesh(new THREE.PlaneBufferGeometry(400, 400), material);
  const grid = new THREE.GridHelper(400, 400, 0x555c68, 0x3a3f48);
  grid.rotation.x = Math.PI / 2;  // GridHelper lies in x-z; the plane geometry in x-y
  grid.position.z = 0.002;
  ground.add(grid);
  const normal = new THREE.Vector3(shape.normal[0], shape.normal[1], shape.normal[2]).normalize();
  ground.quaternion.setFromUnitVectors(new THREE.Vector3(0, 0, 1), normal);
  ground.position.copy(normal).multiplyScalar(shape.offset);
  group.add(ground);
  return group;
}

function geometryOf(shape) {
  switch (shape.type) {
    case 'sphere': return new THREE.SphereBufferGeometry(shape.radius, 20, 14);
    case 'capsule': return capsuleGeometry(shape.radius, shape.half_height);
    case 'box': {
      const h = shape.half_extents;
      return new THREE.BoxBufferGeometry(2 * h[0], 2 * h[1], 2 * h[2]);
    }
    case 'hull': return hullGeometry(shape.points);
    case 'mesh': return meshGeometry(shape.points, shape.indices);
    default: return null;
  }
}

const staticMaterial = new THREE.MeshLambertMaterial({ color: 0x74806f });
const groundMaterial = new THREE.MeshLambertMaterial({ color: 0x2f343c, side: THREE.DoubleSide });
const sleepingMaterial = new THREE.MeshLambertMaterial({ color: 0x34405c });  // dark: asleep
const projectileMaterial = new THREE.MeshLambertMaterial({ color: 0xff8a3d });
const sensorMaterial = new THREE.MeshBasicMaterial({ color: 0x66e0ff, transparent: true, opacity: 0.18, depthWrite: false });
const movingMaterials = [0xd9a441, 0x6cb86a, 0x5aa7d6, 0xc86f8f, 0xa58ad8, 0xd6d06a].map(
  (c) => new THREE.MeshLambertMaterial({ color: c }));

let described = null;   // the scene description the meshes were built from
let meshes = [];        // one per body, in the frame's order
let awakeMaterial = []; // each body's material while awake
const world = new THREE.Group();
scene.add(world);

function buildScene(desc) {
  world.remove(...world.children);
  const geometries = desc.shapes.map((s) => geometryOf(s));
  meshes = [];
  awakeMaterial = [];
  desc.bodies.forEach(([shapeIndex, moving, projectile, sensor], i) => {
    const shape = desc.shapes[shapeIndex];
    const material = sensor ? sensorMaterial : !moving ? staticMaterial : projectile ? projectileMaterial
      : movingMaterials[i % movingMaterials.length];
    let object;
    if (shape.type === 'plane') {
      object = planeObject(shape, groundMaterial);
    } else {
      object = new THREE.Mesh(geometries[shapeIndex], material);
    }
    object.userData.body = i;
    object.userData.moving = !!moving && !sensor;  // a sensor is neither grabbed nor drawn asleep
    object.userData.projectile = !!projectile;
    world.add(object);
    meshes.push(object);
    awakeMaterial.push(material);
  });
  described = desc;
  state.sceneVersion = desc.version;
  state.sceneBodies = desc.bodies.length;
  state.drawnBodies = meshes.length;
  document.getElementById('title').textContent = 'spindle view: ' + desc.name;
}

// ---- contact marks (hit events and, while the box is ticked, the touching points) ----
const contactLines = new THREE.LineSegments(new THREE.BufferGeometry(),
  new THREE.LineBasicMaterial({ color: 0xff4f4f }));
const contactPoints = new THREE.Points(new THREE.BufferGeometry(),
  new THREE.PointsMaterial({ color: 0xffe066, size: 6, sizeAttenuation: false }));
contactLines.frustumCulled = contactPoints.frustumCulled = false;
scene.add(contactLines, contactPoints);
const showContacts = document.getElementById('contacts');

// ---- frames ----
let firstPositions = null;
let latest = null;
let sceneRequest = null;

function readFrame(buffer) {
  const head = new DataView(buffer);
  if (buffer.byteLength < HEADER_BYTES || head.getUint32(0, true) !== FRAME_MAGIC) throw new Error('not a frame');
  const bodies = head.getUint32(8, true), contacts = head.getUint32(12, true);
  const floats = new Float32Array(buffer, HEADER_BYTES, bodies * BODY_FLOATS + contacts * CONTACT_FLOATS);
  return {
    version: head.getUint32(4, true), bodies, contacts, flags: head.getUint32(16, true),
    time: head.getFloat64(24, true), steps: head.getFloat64(32, true), floats,
  };
}

function applyFrame(f) {
  let asleep = 0;
  for (let i = 0; i < f.bodies; i++) {
    const o = i * BODY_FLOATS, m = meshes[i], v = f.floats;
    m.position.set(v[o], v[o + 1], v[o + 2]);
    m.quaternion.set(v[o + 3], v[o + 4], v[o + 5], v[o + 6]);
    if (m.userData.moving && m.isMesh) {
      const sleeping = v[o + 7] > 0.5;
      m.material = sleeping ? sleepingMaterial : awakeMaterial[i];
      asleep += sleeping;
    }
  }
  if (!firstPositions) {
    firstPositions = [];
    frameCamera();
  }
  for (let i = firstPositions.length; i < f.bodies; i++) firstPositions.push(meshes[i].position.clone());
  let moved = state.moved;
  for (let i = 0; i < Math.min(firstPositions.length, f.bodies); i++) {
    moved = Math.max(moved, meshes[i].position.distanceTo(firstPositions[i]));
  }
  state.moved = moved;
  state.asleep = asleep;
  state.flags = f.flags;
  const replay = (f.flags & FLAG_REPLAY) !== 0;
  if (replay && !state.replay) fillSpeeds([0.25, 0.5, 1, 2, 4]);  // a replay may also run fast
  state.replay = replay;
  document.body.classList.toggle('replay', replay);
  const points = [], lines = [];
  if (showContacts.checked) {
    const c0 = f.bodies * BODY_FLOATS;
    for (let k = 0; k < f.contacts; k++) {
      const o = c0 + k * CONTACT_FLOATS, v = f.floats;
      points.push(v[o], v[o + 1], v[o + 2]);
      lines.push(v[o], v[o + 1], v[o + 2], v[o] + 0.5 * v[o + 3], v[o + 1] + 0.5 * v[o + 4], v[o + 2] + 0.5 * v[o + 5]);
    }
  }
  contactPoints.geometry.setAttribute('position', new THREE.Float32BufferAttribute(points, 3));
  contactLines.geometry.setAttribute('position', new THREE.Float32BufferAttribute(lines, 3));
  state.frames += 1;
}

// Aims the camera at the scene's moving bodies once, when the first frame arrives (not
// at balls shot earlier, which may be far off by now).
function frameCamera() {
  const box = new THREE.Box3();
  meshes.forEach((m) => { if (m.userData.moving && !m.userData.projectile) box.expandByPoint(m.position); });
  if (box.isEmpty()) return;
  const size = box.getSize(new THREE.Vector3()).length();
  box.getCenter(orbit.target);
  orbit.distance = Math.max(6, 1.6 * size + 4);
  placeCamera();
}

async function fetchScene() {
  const reply = await fetch('scene', { cache: 'no-store' });
  if (!reply.ok) throw new Error('scene: HTTP ' + reply.status);
  buildScene(await reply.json());
}

async function poll() {
  for (;;) {
    try {
      const reply = await fetch('frame', { cache: 'no-store' });
      if (reply.ok) {
        const frame = readFrame(await reply.arrayBuffer());
        if (!described || frame.version !== described.version) {
          if (!sceneRequest) sceneRequest = fetchScene().finally(() => { sceneRequest = null; });
          await sceneRequest;
        }
        if (described && frame.version === described.version && frame.bodies === meshes.length) latest = frame;
      }
    } catch (e) {
      state.lastError = String(e.message || e);
      await new Promise((r) => setTimeout(r, 500));  // the program stopped, or restarts: try again later
    }
    await new Promise((r) => setTimeout(r, 8));
  }
}

// ---- the panel ----
const numbers = document.getElementById('numbers'), stages = document.getElementById('stages');
function rows(table, list) {
  table.innerHTML = list.map(([k, v]) => `<tr><td>${k}</td><td>${v}</td></tr>`).join('');
}
async function pollStats() {
  for (;;) {
    try {
      const reply = await fetch('stats', { cache: 'no-store' });
      if (reply.ok) showStats(await reply.json());
    } catch (e) { /* the frame poll reports it */ }
    await new Promise((r) => setTimeout(r, 500));
  }
}
function showStats(s) {
  if (s.replay) {
    rows(numbers, [['mode', s.mode + (s.speed !== 1 ? ' x' + s.speed : '')], ['time', s.time.toFixed(2) + ' s'],
                   ['record', s.duration.toFixed(2) + ' s, ' + s.frames + ' frames'], ['bodies', s.bodies]]);
    stages.innerHTML = '';
    const bar = document.getElementById('seekbar');
    bar.max = s.duration;
    if (!seeking) bar.value = s.time;
    return;
  }
  rows(numbers, [
    ['mode', s.mode + (s.speed !== 1 ? ' x' + s.speed : '') + (s.interpolate ? ', interpolated' : ', raw steps')],
    ['steps/s', s.steps_per_second.toFixed(1)], ['steps', s.steps],
    ['bodies (awake)', `${s.bodies} (${s.awake})`], ['touching pairs (awake)', s.contacts],
    ['contact events', `${s.begins} begin, ${s.ends} end, ${s.hits} hit`],
    ['contact points drawn', s.contact_points],
    ['shots, drops, picks', `${s.shots}, ${s.dropped}, ${s.picks}`],
    ['layout ' + s.layout, `game PU ${s.game_pu}, physics PU ${s.physics_pu}`],
    ['worker PUs', s.worker_pus.join(' ')], ['refused requests', s.refused],
  ]);
  rows(stages, s.stages.filter(([, ms]) => ms > 0).map(([name, ms]) => [name, ms.toFixed(3) + ' ms/step']));
}

// ---- commands ----
const message = document.getElementById('message');
async function send(text) {
  try {
    const reply = await fetch('command', { method: 'POST', body: text });
    if (!reply.ok) {
      state.commandsRefused += 1;
      state.lastError = (await reply.text()).trim();
      message.textContent = state.lastError;
      return false;
    }
    message.textContent = '';
    return true;
  } catch (e) {
    message.textContent = state.lastError = String(e.message || e);
    return false;
  }
}
function rayText(ray) {
  const o = ray.origin, d = ray.direction;
  return [o.x, o.y, o.z, d.x, d.y, d.z].map((x) => x.toFixed(5)).join(' ');
}
const raycaster = new THREE.Raycaster();
function rayAt(clientX, clientY) {
  const r = canvas.getBoundingClientRect();
  const ndc = new THREE.Vector2(((clientX - r.left) / r.width) * 2 - 1, -((clientY - r.top) / r.height) * 2 + 1);
  raycaster.setFromCamera(ndc, camera);
  return raycaster.ray;
}
async function shoot(ray) {
  if (await send('shoot ' + rayText(ray))) state.shots += 1;
}

document.getElementById('pause').onclick = () => send('pause');
document.getElementById('resume').onclick = () => send('resume');
document.getElementById('step').onclick = () => send('step');
document.getElementById('drop').onclick = () => send('drop');
document.getElementById('interpolate').onchange = (e) => send('interpolate ' + (e.target.checked ? 'on' : 'off'));
showContacts.onchange = (e) => { if (!state.replay) send('contacts ' + (e.target.checked ? 'on' : 'off')); };
const speed = document.getElementById('speed');
function fillSpeeds(list) {
  speed.innerHTML = list.map((s) => `<option value="${s}"${s === 1 ? ' selected' : ''}>${s}x</option>`).join('');
}
fillSpeeds([1, 0.5, 0.25, 0.1]);
speed.onchange = () => send('speed ' + speed.value);
let seeking = false;
const seekbar = document.getElementById('seekbar');
seekbar.oninput = () => { seeking = true; };
seekbar.onchange = async () => { await send('seek ' + seekbar.value); seeking = false; };

// One drag in flight at a time, the newest waiting: a fast mouse must not queue up
// requests the program would only replace one after another.
let dragBusy = false, dragNext = null;
async function sendDrag(text) {
  if (dragBusy) {
    dragNext = text;
    return;
  }
  dragBusy = true;
  await send(text);
  dragBusy = false;
  if (dragNext) {
    const next = dragNext;
    dragNext = null;
    sendDrag(next);
  }
}

// ---- mouse: click shoots, a drag that starts on a moving body pulls it, else orbits ----
let press = null;
canvas.addEventListener('contextmenu', (e) => e.preventDefault());
canvas.addEventListener('mousedown', (e) => {
  press = { x: e.clientX, y: e.clientY, lastX: e.clientX, lastY: e.clientY, button: e.button, moved: false, grab: false };
  if (e.button !== 0 || state.replay) return;
  rayAt(e.clientX, e.clientY);
  const hits = raycaster.intersectObjects(meshes.filter((m) => m.userData.moving && m.isMesh), false);
  if (hits.length) {
    press.grab = true;
    send('grab ' + rayText(raycaster.ray));
  }
});
window.addEventListener('mousemove', (e) => {
  if (!press) return;
  const dx = e.clientX - press.lastX, dy = e.clientY - press.lastY;
  press.lastX = e.clientX;
  press.lastY = e.clientY;
  if (Math.abs(e.clientX - press.x) + Math.abs(e.clientY - press.y) > 4) press.moved = true;
  if (press.grab) {
    sendDrag('drag ' + rayText(rayAt(e.clientX, e.clientY)));
  } else if (press.button === 2) {  // pan in the view plane
    const scale = orbit.distance / window.innerHeight;
    const right = new THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 0);
    const up = new THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 1);
    orbit.target.addScaledVector(right, -dx * scale).addScaledVector(up, dy * scale);
    placeCamera();
  } else {
    orbit.yaw -= dx * 0.006;
    orbit.pitch += dy * 0.006;
    placeCamera();
  }
});
window.addEventListener('mouseup', (e) => {
  if (!press) return;
  if (press.grab) send('release');
  else if (!press.moved && press.button === 0 && !state.replay) shoot(rayAt(e.clientX, e.clientY));
  press = null;
});
canvas.addEventListener('wheel', (e) => {
  e.preventDefault();
  orbit.distance *= Math.exp(e.deltaY * 0.001);
  placeCamera();
}, { passive: false });

// ---- drawing ----
const stateText = document.getElementById('state');
function draw() {
  if (latest) {
    applyFrame(latest);
    latest = null;
  }
  renderer.render(scene, camera);
  stateText.textContent = JSON.stringify(state);
  requestAnimationFrame(draw);
}

// ?test=shoot: the page tests itself through its own mouse handlers, with synthetic
// events. Once frames arrive it clicks where no moving body is (a shot, as a user's click)
// and notes whether the body count grew and bodies moved; then it presses on the highest
// body, moves the mouse up and notes how far the body rose (a drag). The browser test
// (tests/apps/viewer_test.py) reads the outcome from #state.
function clientAt(ndc) {
  const r = canvas.getBoundingClientRect();
  return { x: r.left + ((ndc.x + 1) / 2) * r.width, y: r.top + ((1 - ndc.y) / 2) * r.height };
}
function mouse(type, at) {
  canvas.dispatchEvent(new MouseEvent(type, { clientX: at.x, clientY: at.y, button: 0, bubbles: true }));
}
function movingAt(at) {
  rayAt(at.x, at.y);
  return raycaster.intersectObjects(meshes.filter((m) => m.userData.moving && m.isMesh), false);
}
async function selfTest() {
  state.test = new URLSearchParams(location.search).get('test') || '';
  if (state.test !== 'shoot') return;
  const pause = (ms) => new Promise((r) => setTimeout(r, ms));
  const until = async (ok) => { while (!ok()) await pause(50); };
  await until(() => state.frames >= 20);
  const before = state.drawnBodies;
  state.bodiesBeforeShot = before;
  const empty = [[0, -0.5], [0.5, -0.5], [-0.5, -0.5], [0, -0.8], [0.8, 0.5]]
    .map(([x, y]) => clientAt(new THREE.Vector2(x, y))).find((at) => movingAt(at).length === 0);
  mouse('mousedown', empty);
  mouse('mouseup', empty);
  await until(() => state.drawnBodies > before);
  state.shotGrew = true;
  await until(() => state.moved > 0.5);

  let top = null;
  meshes.forEach((m) => {
    if (m.userData.moving && !m.userData.projectile && m.isMesh && (!top || m.position.y > top.position.y)) top = m;
  });
  const from = clientAt(top.position.clone().project(camera));
  const y0 = top.position.y;
  state.dragLifted = 0;
  mouse('mousedown', from);
  for (let i = 1; i <= 10; i++) {
    await pause(30);
    mouse('mousemove', { x: from.x, y: from.y - 8 * i });
  }
  for (let i = 0; i < 100 && top.position.y - y0 < 0.5; i++) {
    await pause(50);
    state.dragLifted = top.position.y - y0;
  }
  state.dragLifted = top.position.y - y0;
  mouse('mouseup', { x: from.x, y: from.y - 80 });
  state.testDone = true;
}

requestAnimationFrame(draw);
poll();
pollStats();
selfTest();
