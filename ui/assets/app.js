// The orthoflow live view: reads the state over the WebSocket /api/events (JSON documents, see
// ui/ui_json.hpp), draws it, and sends teach / correct / ask / forget / undo to the JSON API, and
// starts and stops the table tasks (POST /api/task/start, /api/task/stop).
'use strict';

const params = new URLSearchParams(location.search);
const token = params.get('token') || '';
let state = null;
let selected = null;  // track id

const $ = (id) => document.getElementById(id);

function cell(row, text, cls) {
  const td = row.insertCell();
  td.textContent = text;
  if (cls) td.className = cls;
  return td;
}

function fill(tableId, items, render) {
  const body = $(tableId).tBodies[0];
  body.replaceChildren();
  for (const item of items) render(body.insertRow(), item);
}

function fmt(v, digits) { return v === null || v === undefined ? '-' : Number(v).toFixed(digits); }

function mainObjects(s) { return s.objects.filter((o) => !o.fragment && o.track !== 0); }

function renderObjects(s) {
  fill('objects', mainObjects(s), (row, o) => {
    if (o.track === selected) row.className = 'selected';
    row.dataset.track = o.track;
    cell(row, o.track);
    if (o.label === null) cell(row, 'Unknown', 'unknown'); else cell(row, o.label);
    cell(row, fmt(o.score, 3));
    cell(row, o.points);
    cell(row, o.centroid.map((c) => fmt(c, 2)).join(', '));
  });
}

function renderMemory(s) {
  fill('memory', s.memory, (row, c) => {
    cell(row, c.label);
    cell(row, c.views);
    cell(row, c.last_taught_ms ? new Date(c.last_taught_ms).toLocaleTimeString() : '-');
  });
  // The completion list is rebuilt only when the categories change: rebuilding it at every update
  // would close the browser's suggestion popup while the person types.
  const labels = s.memory.map((c) => c.label).join('\n');
  const list = $('categories');
  if (list.dataset.labels === labels) return;
  list.dataset.labels = labels;
  list.replaceChildren();
  for (const c of s.memory) {
    const option = document.createElement('option');
    option.value = c.label;
    list.appendChild(option);
  }
}

function renderEvents(s) {
  fill('events', s.events.slice().reverse(), (row, e) => {
    cell(row, e.id);
    cell(row, e.action);
    cell(row, e.action === 'forget' || e.action === 'undo' ? '-' : e.track);
    cell(row, e.label || (e.action === 'ask' ? 'Unknown' : ''));
    cell(row, e.outcome, e.ok ? 'good' : 'bad');
  });
}

function renderLatency(s) {
  const t = s.telemetry;
  $('graph').textContent = `${t.frames} frames, ${t.drops} dropped, frame p99 ${fmt(t.frame_p99_us, 0)} us` +
      (s.durable ? ', memory on disk' : ', memory in RAM');
  fill('latency', t.nodes, (row, n) => {
    cell(row, n.name);
    cell(row, n.processed);
    cell(row, n.dropped);
    cell(row, fmt(n.p50_us, 0));
    cell(row, fmt(n.p99_us, 0));
    cell(row, fmt(n.max_us, 0));
  });
}

// Top view: sensor x to the right, depth z upwards, fitted to the objects with a margin.
function viewBox(objects) {
  let x0 = -0.4, x1 = 0.4, z0 = 0.6, z1 = 1.4;
  for (const o of objects) {
    x0 = Math.min(x0, o.bbox_min[0]); x1 = Math.max(x1, o.bbox_max[0]);
    z0 = Math.min(z0, o.bbox_min[2]); z1 = Math.max(z1, o.bbox_max[2]);
  }
  return {x0: x0 - 0.05, x1: x1 + 0.05, z0: z0 - 0.05, z1: z1 + 0.05};
}

function projector(canvas, box) {
  const scale = Math.min(canvas.width / (box.x1 - box.x0), canvas.height / (box.z1 - box.z0));
  return (x, z) => [(x - box.x0) * scale, canvas.height - (z - box.z0) * scale];
}

function drawTop(s) {
  const canvas = $('top');
  const g = canvas.getContext('2d');
  g.clearRect(0, 0, canvas.width, canvas.height);
  const objects = mainObjects(s).filter((o) => o.centroid.every((c) => c !== null));
  const at = projector(canvas, viewBox(objects));
  canvas.objectsAt = [];
  for (const o of objects) {
    const [ax, ay] = at(o.bbox_min[0], o.bbox_min[2]);
    const [bx, by] = at(o.bbox_max[0], o.bbox_max[2]);
    g.fillStyle = o.label === null ? '#b0bec588' : '#4caf5088';
    g.strokeStyle = o.track === selected ? '#f57f17' : '#37474f';
    g.lineWidth = o.track === selected ? 3 : 1;
    g.fillRect(ax, by, bx - ax, ay - by);
    g.strokeRect(ax, by, bx - ax, ay - by);
    const [cx, cy] = at(o.centroid[0], o.centroid[2]);
    g.fillStyle = '#222';
    g.font = '12px sans-serif';
    g.fillText(`#${o.track} ${o.label === null ? 'Unknown' : o.label}`, ax, by - 4);
    canvas.objectsAt.push({track: o.track, x: cx, y: cy});
  }
}

// The camera image (GET /api/camera.png: the newest frame with the objects' boxes drawn on it).
// The stream (opened with camera=1) keeps the server drawing images and says in state.camera which
// frame the newest one shows; the page fetches it only when that frame is new and the last one has
// arrived, at most 5 times a second, so it never asks for an image the server does not have.
let cameraLoading = false, cameraNext = 0, cameraFrame = 0;
function refreshCamera(s) {
  const now = Date.now();
  if (!s.camera || s.camera.frame === cameraFrame || cameraLoading || now < cameraNext) return;
  cameraLoading = true;
  cameraNext = now + 200;
  cameraFrame = s.camera.frame;
  const q = new URLSearchParams({n: String(now)});
  if (token) q.set('token', token);
  $('camera').src = `/api/camera.png?${q}`;
}
$('camera').addEventListener('load', () => {
  cameraLoading = false;
  $('camera').hidden = false;
  $('camera-none').hidden = true;
});
$('camera').addEventListener('error', () => {
  cameraLoading = false;
  cameraNext = Date.now() + 2000;
  $('camera').hidden = true;
  $('camera-none').hidden = false;
});
// Click an object in the camera image: the smallest box (state.camera) under the pointer.
$('camera').addEventListener('click', (event) => {
  const c = state && state.camera;
  if (!c) return;
  const r = $('camera').getBoundingClientRect();
  const u = (event.clientX - r.left) * c.width / r.width;
  const v = (event.clientY - r.top) * c.height / r.height;
  let best = null, bestArea = Infinity;
  for (const b of c.boxes) {
    const [u0, v0, u1, v1] = b.box;
    const area = (u1 - u0) * (v1 - v0);
    if (u >= u0 && u <= u1 && v >= v0 && v <= v1 && area < bestArea) { best = b.track; bestArea = area; }
  }
  if (best !== null) select(best);
});

function renderTask(s) {
  const t = s.task;
  for (const b of document.querySelectorAll('#task button')) b.disabled = !s.tasks;
  if (!s.tasks) {
    $('task-state').textContent = 'no task control here (the graph needs --ipc-learning)';
  } else if (t === null) {
    $('task-state').textContent = 'no `orthoflow task run` answering';
  } else {
    let text = `${t.task}: ${t.state}`;
    if (t.state === 'running') text += `, move ${t.move} of ${t.moves} (${t.phase}), ${t.done} done`;
    if (t.state === 'finished') text += `, ${t.done} of ${t.moves} moves done`;
    if (t.message) text += ` (${t.message})`;
    $('task-state').textContent = text;
  }
}

// POSTs @p body as JSON (with the bearer token when the page has one) and returns the answer
// document; shows "WHAT..." in @p line meanwhile, and WHAT failed: ... there when no answer came.
async function postJson(path, body, line, what) {
  const headers = {'Content-Type': 'application/json'};
  if (token) headers.Authorization = `Bearer ${token}`;
  $(line).textContent = `${what}...`;
  try {
    const response = await fetch(path, {method: 'POST', headers, body: JSON.stringify(body)});
    return await response.json();
  } catch (e) {
    $(line).textContent = `${what} failed: ${e}`;
    $(line).className = 'bad';
    return null;
  }
}

async function task(which) {
  let path = '/api/task/start', body = {task: which};
  if (which === 'stop') { path = '/api/task/stop'; body = {}; }
  if (which === 'serve_a_meal') {
    body.bring = $('bring').value.split(',').map((c) => c.trim()).filter((c) => c.length > 0);
    if (body.bring.length === 0) { $('task-answer').textContent = 'name the categories to bring'; return; }
  }
  const answer = await postJson(path, body, 'task-answer', which);
  if (answer === null) return;
  $('task-answer').textContent = answer.error ? `${which}: ${answer.error}`
    : `${which}: ${answer.answer}${answer.message ? ` (${answer.message})` : ''}`;
  $('task-answer').className = answer.ok ? 'good' : 'bad';
}

// The arm's stop button (POST /api/arm/stop): the process holding the arm halts it and latches.
$('arm-stop').addEventListener('click', async () => {
  const answer = await postJson('/api/arm/stop', {}, 'arm-stop-answer', 'stopping the arm');
  if (answer === null) return;
  $('arm-stop-answer').textContent = answer.error ? `arm stop: ${answer.error}`
    : `arm halted (${answer.was_moving ? 'was moving' : 'was still'}); latched until orthoflow arm reset`;
  $('arm-stop-answer').className = answer.ok ? 'good' : 'bad';
});

for (const button of document.querySelectorAll('#task button')) {
  button.addEventListener('click', () => task(button.dataset.task));
}

function render(s) {
  state = s;
  renderTask(s);
  refreshCamera(s);
  // The table verdict: a robot that sees no table says so, and why (docs/SEGMENTATION.md).
  const t = s.table;
  const table = !t ? '' : t.found ? ` · table ${t.reason} (up: ${t.gravity})`
                                  : ` · NO TABLE: ${t.reason} (up: ${t.gravity})`;
  $('frame').textContent = `frame ${s.frame} (${fmt(s.age_ms, 1)} ms old)${table}`;
  renderObjects(s);
  renderMemory(s);
  renderEvents(s);
  renderLatency(s);
  drawTop(s);
}

function select(track) {
  selected = track;
  $('selected').textContent = `track ${track}`;
  if (state) render(state);
}

// Rows are rebuilt at every update (up to the frame rate), so a press and its release can land on two
// different row elements and no click event reaches either: select on the press, delegated from the
// table body, which stays.
$('objects').tBodies[0].addEventListener('pointerdown', (event) => {
  const row = event.target.closest('tr');
  if (row && row.dataset.track !== undefined) select(Number(row.dataset.track));
});

$('top').addEventListener('click', (event) => {
  const canvas = $('top');
  const r = canvas.getBoundingClientRect();
  const x = (event.clientX - r.left) * canvas.width / r.width;
  const y = (event.clientY - r.top) * canvas.height / r.height;
  let best = null, bestDistance = 40 * 40;
  for (const o of canvas.objectsAt || []) {
    const d = (o.x - x) ** 2 + (o.y - y) ** 2;
    if (d < bestDistance) { best = o.track; bestDistance = d; }
  }
  if (best !== null) select(best);
});

async function act(action) {
  const label = $('label').value.trim();
  const body = action === 'forget' ? {label} : action === 'undo' ? {}
    : action === 'ask' ? {track: selected} : {track: selected, label};
  if (action !== 'forget' && action !== 'undo' && selected === null) { $('answer').textContent = 'click an object first'; return; }
  const answer = await postJson(`/api/${action}`, body, 'answer', action);
  if (answer === null) return;
  let text = `${action}: ${answer.outcome || answer.error}`;
  if (action === 'ask' && answer.ok) {
    text += ` -> ${answer.answer === null ? 'Unknown' : answer.answer}`;
    const near = answer.nearest.map((n) => n.score === null ? n.label : `${n.label} ${fmt(n.score, 3)}`);
    if (near.length > 0) text += `; nearest: ${near.join(', ')}`;
  }
  if (action === 'undo' && answer.ok) text += `: ${answer.views} view(s) of "${answer.label}" taken back`;
  if (!answer.ok && answer.error && answer.outcome) text += ` (${answer.error})`;  // else shown above
  if (answer.ok && answer.outcome === 'stored') text += ' (on disk)';
  $('answer').textContent = text;
  $('answer').className = answer.ok ? 'good' : 'bad';
}

for (const button of document.querySelectorAll('#action button')) {
  button.addEventListener('click', () => act(button.dataset.action));
}

function connect() {
  // The page's ?hz= chooses the rate; camera=1 keeps the camera images coming while it is open.
  const q = new URLSearchParams({hz: params.get('hz') || '10', camera: '1'});
  if (token) q.set('token', token);
  const ws = new WebSocket(`${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}/api/events?${q}`);
  ws.onopen = () => { $('status').textContent = 'live'; };
  ws.onmessage = (m) => render(JSON.parse(m.data));
  ws.onclose = () => { $('status').textContent = 'disconnected, retrying...'; setTimeout(connect, 1000); };
}
connect();
