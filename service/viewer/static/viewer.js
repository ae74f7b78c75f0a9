// golfflight live shot viewer: reads the service's server-sent events (GET /v1/events, one ShotEvent per shot: see
// service/viewer/event.schema.json) and draws each shot from behind the golfer, from the side and from above, with
// its numbers, a shot table and the landing dispersion per club. Plain JavaScript and SVG, nothing from elsewhere.
"use strict";

const YARD_M = 0.9144;
const MPH_MPS = 0.44704;
const KEEP_SHOTS = 50;            // as many as the service keeps
const PLAY_S = 3;                 // the newest shot plays back in real time, but never longer than this
const SVG_NS = "http://www.w3.org/2000/svg";
const KEY_STORE = "golfflight-api-key";
const SOURCES = { "http": "HTTP", "batch": "batch", "gspro-http": "GSPro (HTTP)", "open-connect": "Open Connect" };
const CLUB_COLOURS = ["#ffd23f", "#4cd07d", "#5bc0ff", "#ff8a5b", "#c38bff", "#ff5b9a", "#9be15d", "#f2f2f2"];
const BAY_SOURCES = new Set(["http", "gspro-http", "open-connect"]);  // hit in this bay: tagged with its club
const STALL_MS = 45_000;          // the service sends a keep-alive comment every 15 s: silence this long is a dead link
const BAY_POLL_MS = 30_000;       // how often the bay's conditions are read again (another screen may change them)
const FEET_M = 0.3048;

const state = {
  shots: [],                       // newest last: {event, club}
  units: localStorage.getItem("golfflight-units") || "imperial",  // the bay's `units` once read (GET /v1/bay)
  bay: null,                       // the bay's conditions as the service last gave them
  key: initialKey(),
  lastId: null,
  play: null,                      // {id, started, speed, end}
  ticking: false,
};

/** The newest shot's polyline and ball in each view while it plays: all that an animation frame redraws. */
const live = [];

// ---- units: SI inside; yards and mph only on screen, by the toggle -------------------------------------------

function imperial() { return state.units === "imperial"; }
function distUnit() { return imperial() ? "yd" : "m"; }

/** A distance from a flight result: its own `name_yd` field when it has one, else `name_m` converted; null if
 * the result has neither (e.g. total and roll before the ground phase). */
function distance(flight, name) {
  if (imperial() && typeof flight[name + "_yd"] === "number") return flight[name + "_yd"];
  const metres = flight[name + "_m"];
  if (typeof metres !== "number") return null;
  return imperial() ? metres / YARD_M : metres;
}

function fixed(value, digits = 1) {
  return value === null || value === undefined ? "—" : value.toFixed(digits);
}

function speedText(mps) { return fixed(imperial() ? mps / MPH_MPS : mps); }
function speedUnit() { return imperial() ? "mph" : "m/s"; }
function rpm(value) { return Math.round(value).toLocaleString("en-US"); }

/** + = right, written as golfers read it: [the size, "R" or "L" ("" when it rounds to 0)]. */
function side(value, digits = 1) {
  if (value === null) return ["—", ""];
  const text = Math.abs(value).toFixed(digits);
  return [text, Number(text) === 0 ? "" : value > 0 ? "R" : "L"];
}

// ---- the key ------------------------------------------------------------------------------------------------

/** The API key from the URL fragment (#key=..., never sent to the server; removed from the address bar at once)
 * or from this tab's session storage. */
function initialKey() {
  const match = location.hash.match(/(?:^#|&)key=([^&]*)/);
  if (match) {
    sessionStorage.setItem(KEY_STORE, decodeURIComponent(match[1]));
    history.replaceState(null, "", location.pathname + location.search);
  }
  return sessionStorage.getItem(KEY_STORE) || "";
}

function askForKey(message) {
  setStatus("key", message);
  const form = document.getElementById("key-form");
  form.hidden = false;
  document.getElementById("key").focus();
}

// ---- the event stream ---------------------------------------------------------------------------------------

function setStatus(kind, text) {
  const status = document.getElementById("status");
  status.dataset.state = kind;
  status.textContent = text;
}

const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

/** Reads /v1/events for as long as the page is open. fetch() and not EventSource: EventSource cannot send the
 * X-API-Key header. The stream stays open (a `: keep-alive` comment every 15 s when no shot comes); one that ends
 * (a restarting service) or stays silent for STALL_MS is reopened at once with Last-Event-ID, so no kept shot is
 * missed; a failure waits a little longer. */
async function follow() {
  for (;;) {
    let pause = 100;
    try {
      const headers = { "Accept": "text/event-stream" };
      if (state.key) headers["X-API-Key"] = state.key;
      if (state.lastId !== null) headers["Last-Event-ID"] = String(state.lastId);
      const abort = new AbortController();
      const response = await fetch("v1/events", { headers, cache: "no-store", signal: abort.signal });
      if (response.status === 401) {
        askForKey(state.key ? "wrong API key" : "API key needed");
        return;
      }
      if (response.ok) {
        setStatus("live", "live");
        await readEvents(response.body, abort);
      } else {
        const answer = await response.json().catch(() => ({}));
        setStatus("down", `stream refused (${response.status}): ${answer.detail || "retrying"}`);
        pause = 3000;
      }
    } catch (error) {
      setStatus("down", "service unreachable: retrying");
      pause = 2000;
    }
    await sleep(pause);
  }
}

async function readEvents(body, abort) {
  const reader = body.pipeThrough(new TextDecoderStream()).getReader();
  let buffer = "";
  for (;;) {
    const stalled = setTimeout(() => abort.abort(), STALL_MS);
    const { value, done } = await reader.read().finally(() => clearTimeout(stalled));
    if (done) return;
    buffer += value;
    let cut;
    while ((cut = buffer.indexOf("\n\n")) >= 0) {
      onBlock(buffer.slice(0, cut));
      buffer = buffer.slice(cut + 2);
    }
  }
}

/** One server-sent event: `id:`, `event:` and `data:` lines; comments and `retry:` are skipped. */
function onBlock(block) {
  let id = null, kind = "message";
  const data = [];
  for (const line of block.split("\n")) {
    if (!line || line.startsWith(":")) continue;
    const colon = line.indexOf(":");
    const field = colon < 0 ? line : line.slice(0, colon);
    const value = colon < 0 ? "" : line.slice(colon + 1).replace(/^ /, "");
    if (field === "id") id = value;
    else if (field === "event") kind = value;
    else if (field === "data") data.push(value);
  }
  if (id !== null) state.lastId = Number(id);
  if (kind === "shot" && data.length) addShot(JSON.parse(data.join("\n")));
}

function addShot(event) {
  const seen = state.shots.some((s) => s.event.id === event.id && s.event.received_unix_s === event.received_unix_s);
  if (seen) return;
  // the bay's own shots get the club picked now; batches (shown only when their request asked) get none
  const club = BAY_SOURCES.has(event.source) ? document.getElementById("club").value : "";
  state.shots.push({ event, club });
  if (state.shots.length > KEEP_SHOTS) state.shots.shift();
  const points = event.flight.trajectory;
  const end = points[points.length - 1].t_s;
  state.play = { id: event.id, started: performance.now(), speed: Math.max(1, end / PLAY_S), end };
  render();
  if (!state.ticking) {
    state.ticking = true;
    requestAnimationFrame(tick);
  }
}

// ---- drawing ------------------------------------------------------------------------------------------------

function el(parent, name, attrs = {}, text) {
  const node = document.createElementNS(SVG_NS, name);
  for (const [key, value] of Object.entries(attrs)) node.setAttribute(key, value);
  if (text !== undefined) node.textContent = text;
  parent.appendChild(node);
  return node;
}

function latest() { return state.shots.length ? state.shots[state.shots.length - 1] : null; }

/** The trajectory of a shot up to the playback time (all of it for every shot but the one playing). */
function shown(shot) {
  const points = shot.event.flight.trajectory;
  const play = state.play;
  if (!play || play.id !== shot.event.id) return points;
  const t = ((performance.now() - play.started) / 1000) * play.speed;
  if (t >= play.end) return points;
  const upto = points.filter((p) => p.t_s <= t);
  const next = points[upto.length];
  if (upto.length && next) {
    const a = upto[upto.length - 1], f = (t - a.t_s) / (next.t_s - a.t_s);
    upto.push({ t_s: t, x_m: a.x_m + f * (next.x_m - a.x_m), y_m: a.y_m + f * (next.y_m - a.y_m), z_m: a.z_m + f * (next.z_m - a.z_m) });
  }
  return upto;
}

function playing() {
  const play = state.play;
  return play && (performance.now() - play.started) / 1000 * play.speed < play.end;
}

/** The scene's size in metres: downrange to a round number of the unit shown, height, lateral spread. */
function extent() {
  const step = 50 * (imperial() ? YARD_M : 1);
  let far = 0, high = 0, wide = 0;
  for (const shot of state.shots) {
    for (const p of shot.event.flight.trajectory) {
      far = Math.max(far, p.y_m); high = Math.max(high, p.z_m); wide = Math.max(wide, Math.abs(p.x_m));
    }
  }
  return { step, far: Math.max(2, Math.ceil((far * 1.05) / step)) * step, high: Math.max(10, high * 1.15), wide: Math.max(15, wide * 1.2) };
}

function points(list, project) {
  return list.map((p) => project(p).map((v) => v.toFixed(1)).join(",")).join(" ");
}

/** A whole path's points in a view, worked out once per shot and kept while the view's scale (`scene`) holds. */
function pathPoints(shot, svg, scene, project) {
  const kept = (shot.paths ||= {})[svg.id];
  if (kept && kept.scene === scene) return kept.text;
  const text = points(shot.event.flight.trajectory, project);
  shot.paths[svg.id] = { scene, text };
  return text;
}

/** Every shot as a polyline in one view (`scene`: its scale, for the kept points), the newest highlighted and
 * flown as it plays; its landing and rest points once it has come down. */
function drawShots(svg, project, scene) {
  const newest = latest();
  const moving = playing();
  let newestLine = null;
  for (const shot of state.shots) {
    const isNew = shot === newest;
    const line = el(svg, "polyline", {
      class: "path " + (isNew ? "latest" : "old"),
      points: isNew && moving ? points(shown(shot), project) : pathPoints(shot, svg, scene, project),
      "data-shot": shot.event.id,
    });
    if (isNew) newestLine = line;
  }
  if (!newest) return;
  const flight = newest.event.flight;
  if (moving) {
    const path = shown(newest);
    const [x, y] = project(path[path.length - 1] || flight.trajectory[0]);
    const ball = el(svg, "circle", { class: "ball", cx: x, cy: y, r: 4 });
    live.push({ line: newestLine, ball, project });
    return;
  }
  newestLine.dataset.done = "1";
  const [lx, ly] = project({ x_m: flight.landing.x_m, y_m: flight.landing.y_m, z_m: 0 });
  el(svg, "circle", { class: "landing", cx: lx, cy: ly, r: 6 });
  if (flight.rest) {
    const [rx, ry] = project({ x_m: flight.rest.x_m, y_m: flight.rest.y_m, z_m: 0 });
    el(svg, "circle", { class: "rest", cx: rx, cy: ry, r: 4 });
  }
}

function unitLabel(metres) { return `${Math.round(metres / (imperial() ? YARD_M : 1))} ${distUnit()}`; }

/** From behind the golfer: a camera 40 m behind the tee and 12 m up, on the target line, looking level down it;
 * zoomed so that every path fits, the tee at the bottom centre and the target line running straight up the middle to
 * the vanishing point (the horizon). A straight shot (direction 0, spin axis 0, no crosswind) stays on that line.
 * Every distance line is labelled, the labels alternating right and left of the fairway so that the far ones, which
 * perspective crowds together, still have room. What was drawn is kept on `window.golfflightViewer.behind`. */
function drawBehind(svg, box) {
  svg.replaceChildren();
  const W = 800, H = 800, back = 40, eye = 12, margin = 24;
  const view = (p) => {
    const depth = Math.max(p.y_m + back, 0.5);
    return [p.x_m / depth, (p.z_m - eye) / depth];
  };
  const low = view({ x_m: 0, y_m: 0, z_m: 0 })[1];           // the tee, below the horizon
  let high = 0.05, wide = 0.05;
  for (const shot of state.shots) {
    for (const p of shot.event.flight.trajectory) {
      const [u, v] = view(p);
      high = Math.max(high, v); wide = Math.max(wide, Math.abs(u));
    }
  }
  const scale = Math.min((H - 2 * margin) / (high - low), (W / 2 - margin) / wide);
  const bottom = H - margin;
  const horizon = bottom + low * scale;                        // so that the tee lands on `bottom`
  const project = (p) => {
    const [u, v] = view(p);
    return [W / 2 + u * scale, horizon - v * scale];
  };
  const defs = el(svg, "defs");
  const sky = el(defs, "linearGradient", { id: "sky", x1: 0, y1: 0, x2: 0, y2: 1 });
  el(sky, "stop", { offset: "0", "stop-color": "#0f2740" });
  el(sky, "stop", { offset: "1", "stop-color": "#3d6d8f" });
  el(svg, "rect", { class: "sky", x: 0, y: 0, width: W, height: horizon });
  el(svg, "rect", { class: "rough", x: 0, y: horizon, width: W, height: H - horizon });
  const half = 20;
  const corners = [[-half, 0], [half, 0], [half, box.far], [-half, box.far]];
  el(svg, "polygon", { class: "fairway", points: points(corners.map(([x, y]) => ({ x_m: x, y_m: y, z_m: 0 })), project) });
  const lines = [];
  for (let y = box.step; y <= box.far + 1e-6; y += box.step) lines.push(y);
  const ys = lines.map((y) => project({ x_m: 0, y_m: y, z_m: 0 })[1]);
  const labels = [];
  lines.forEach((y, n) => {
    const [x1, y1] = project({ x_m: -half * 1.5, y_m: y, z_m: 0 });
    const [x2] = project({ x_m: half * 1.5, y_m: y, z_m: 0 });
    el(svg, "line", { class: "marker-line", x1, y1, x2, y2: y1 });
    const onLeft = n % 2 === 1;
    // above its line, as tall as the gap to the next line on the same side allows (that label sits above it)
    const room = n + 2 < lines.length ? ys[n] - ys[n + 2] - 1 : 20;
    const size = Math.max(9, Math.min(20, room));
    const label = el(svg, "text", { class: "label distance", y: y1 - 2, "text-anchor": onLeft ? "end" : "start" }, unitLabel(y));
    label.style.fontSize = `${size.toFixed(1)}px`;  // CSSOM: the page's CSP allows no inline style attribute
    const length = label.getComputedTextLength() || 4 * size;  // beside the line's end, always inside the picture
    label.setAttribute("x", (onLeft ? Math.max(x1 - 6, length + 4) : Math.min(x2 + 6, W - length - 4)).toFixed(1));
    labels.push({ text: label.textContent, y: y1, size });
  });
  const [tx, ty] = project({ x_m: 0, y_m: 0, z_m: 0 });
  el(svg, "line", { class: "target-line", x1: tx, y1: ty, x2: W / 2, y2: horizon });
  el(svg, "circle", { class: "tee", cx: tx, cy: ty, r: 3 });
  drawShots(svg, project, `${scale} ${horizon}`);
  (window.golfflightViewer ||= {}).behind = { width: W, height: H, tee: [tx, ty], vanishing: [W / 2, horizon], labels };
}

/** From the side: downrange to the right, height up, one scale for both. */
function drawSide(svg, box) {
  svg.replaceChildren();
  const W = 800, H = 250, left = 46, bottom = 22;
  const scale = Math.min((W - left - 14) / box.far, (H - bottom - 12) / box.high);
  const project = (p) => [left + p.y_m * scale, H - bottom - p.z_m * scale];
  for (let y = 0; y <= box.far + 1e-6; y += box.step) {
    const x = left + y * scale;
    el(svg, "line", { class: "grid", x1: x, y1: 8, x2: x, y2: H - bottom });
    el(svg, "text", { class: "label", x: x - 12, y: H - 6 }, unitLabel(y));
  }
  const heightStep = imperial() ? 10 * YARD_M : 10;
  for (let z = heightStep; z * scale < H - bottom - 8; z += heightStep) {
    el(svg, "text", { class: "label", x: 4, y: H - bottom - z * scale + 4 }, unitLabel(z));
  }
  el(svg, "line", { class: "ground-line", x1: left, y1: H - bottom, x2: W, y2: H - bottom });
  drawShots(svg, project, String(scale));
}

/** From above: downrange to the right, the golfer's right downwards, one scale for both. */
function drawTop(svg, box) {
  svg.replaceChildren();
  const W = 800, H = 250, left = 46;
  const scale = Math.min((W - left - 14) / box.far, (H - 20) / (2 * box.wide));
  const project = (p) => [left + p.y_m * scale, H / 2 + p.x_m * scale];
  el(svg, "rect", { class: "fairway", x: left, y: H / 2 - 20 * scale, width: box.far * scale, height: 40 * scale, opacity: 0.5 });
  for (let y = 0; y <= box.far + 1e-6; y += box.step) {
    const x = left + y * scale;
    el(svg, "line", { class: "grid", x1: x, y1: 0, x2: x, y2: H });
  }
  el(svg, "line", { class: "target-line", x1: left, y1: H / 2, x2: W, y2: H / 2 });
  el(svg, "text", { class: "label", x: 4, y: 14 }, "left");
  el(svg, "text", { class: "label", x: 4, y: H - 6 }, "right");
  drawShots(svg, project, String(scale));
}

/** Landing points (filled) and rest points (rings, once the results carry them) per club, seen from behind. */
function drawDispersion(svg, box) {
  svg.replaceChildren();
  const S = 400, pad = 34;
  const clubs = [...new Set(state.shots.map((s) => s.club))];
  const colour = (club) => CLUB_COLOURS[clubs.indexOf(club) % CLUB_COLOURS.length];
  const wide = Math.max(box.wide, box.far / 8);
  const sx = (S - 2 * pad) / (2 * wide), sy = (S - 2 * pad) / box.far;
  const project = (x, y) => [S / 2 + x * sx, S - pad - y * sy];
  for (let y = 0; y <= box.far + 1e-6; y += box.step) {
    const [, py] = project(0, y);
    el(svg, "line", { class: "grid", x1: pad, y1: py, x2: S - pad, y2: py });
    el(svg, "text", { class: "label", x: 2, y: py + 4 }, unitLabel(y));
  }
  el(svg, "line", { class: "target-line", x1: S / 2, y1: pad / 2, x2: S / 2, y2: S - pad });
  // rest rings first and in the club's colour (CSSOM: a stroke attribute loses to the .dot rule, which drew them
  // dark over the landing dots as half discs), then the landing dots, whole, on top
  for (const shot of state.shots) {
    const flight = shot.event.flight;
    if (!flight.rest) continue;
    const [rx, ry] = project(flight.rest.x_m, flight.rest.y_m);
    el(svg, "circle", { class: "dot rest-dot", cx: rx, cy: ry, r: 5 }).style.stroke = colour(shot.club);
  }
  for (const shot of state.shots) {
    const flight = shot.event.flight;
    const [x, y] = project(flight.landing.x_m, flight.landing.y_m);
    el(svg, "circle", { class: "dot", cx: x, cy: y, r: 5, fill: colour(shot.club), "data-shot": shot.event.id });
  }
  const legend = document.getElementById("legend");
  legend.replaceChildren();
  for (const club of clubs) {
    const group = state.shots.filter((s) => s.club === club);
    const carries = group.map((s) => distance(s.event.flight, "carry"));
    const mean = carries.reduce((a, b) => a + b, 0) / carries.length;
    const item = document.createElement("li");
    item.style.setProperty("--swatch", colour(club));
    item.textContent = `${club || "no club"}: ${group.length} shot${group.length > 1 ? "s" : ""}, carry ${mean.toFixed(1)} ${distUnit()} on average`;
    legend.appendChild(item);
  }
}

// ---- numbers ------------------------------------------------------------------------------------------------

/** A tile's number, its unit small after it, and the side (R or L) after that. */
function setNumber(id, text, unit, hand = "") {
  const node = document.getElementById(id);
  node.textContent = text;
  if (unit && text !== "—") {
    const small = document.createElement("small");
    small.textContent = unit;
    if (unit === "°") small.className = "deg";  // 10.4°, not 10.4 °
    node.append(small, hand ? "\u00a0" + hand : "");
  }
}

function spinParts(launch) {
  const axis = (launch.spin_axis_deg * Math.PI) / 180;
  return { back: launch.spin_rpm * Math.cos(axis), side: launch.spin_rpm * Math.sin(axis) };
}

function showNumbers(shot) {
  document.getElementById("last-source").textContent = shot
    ? `#${shot.event.id} · ${SOURCES[shot.event.source]}${shot.event.shot_number ? " shot " + shot.event.shot_number : ""}` : "";
  if (!shot) return;
  const { launch, flight } = shot.event;
  const spin = spinParts(launch);
  const unit = distUnit();
  setNumber("n-ball-speed", speedText(launch.ball_speed_mps), speedUnit());
  setNumber("n-launch", fixed(launch.launch_angle_deg), "°");
  const [direction, directionHand] = side(launch.launch_direction_deg);
  setNumber("n-direction", direction, "°", directionHand);
  setNumber("n-back-spin", rpm(spin.back), "rpm");
  const [sideSpin, spinHand] = side(spin.side, 0);
  setNumber("n-side-spin", sideSpin, "rpm", spinHand);
  setNumber("n-carry", fixed(distance(flight, "carry")), unit);
  setNumber("n-total", fixed(distance(flight, "total")), unit);
  setNumber("n-roll", fixed(distance(flight, "roll")), unit);
  setNumber("n-apex", fixed(distance(flight, "apex")), unit);
  setNumber("n-landing-angle", fixed(flight.landing_angle_deg), "°");
  const [lateral, lateralHand] = side(distance(flight, "lateral"));
  setNumber("n-lateral", lateral, unit, lateralHand);
  setNumber("n-flight-time", fixed(flight.flight_time_s), "s");
}

function showTable() {
  const body = document.querySelector("#shots tbody");
  body.replaceChildren();
  for (const shot of [...state.shots].reverse()) {
    const { launch, flight } = shot.event;
    const row = document.createElement("tr");
    row.dataset.shot = shot.event.id;
    const cells = [
      shot.event.id, SOURCES[shot.event.source], shot.club || "—",
      `${speedText(launch.ball_speed_mps)} ${speedUnit()}`, `${fixed(launch.launch_angle_deg)}°`, rpm(launch.spin_rpm),
      fixed(distance(flight, "carry")), fixed(distance(flight, "total")), fixed(distance(flight, "apex")),
      `${fixed(flight.landing_angle_deg)}°`, side(distance(flight, "lateral")).join(" ").trim(),
    ];
    for (const text of cells) {
      const cell = document.createElement("td");
      cell.textContent = text;
      row.appendChild(cell);
    }
    body.appendChild(row);
  }
  const head = document.querySelectorAll("#shots th");
  for (const [index, name] of [[6, "carry"], [7, "total"], [8, "apex"], [10, "lateral"]]) {
    head[index].textContent = `${name} (${distUnit()})`;
  }
}

function drawViews() {
  live.length = 0;
  const box = extent();
  drawBehind(document.getElementById("behind"), box);
  drawSide(document.getElementById("side"), box);
  drawTop(document.getElementById("top"), box);
  return box;
}

function render() {
  const box = drawViews();
  drawDispersion(document.getElementById("dispersion"), box);
  showNumbers(latest());
  showTable();
  for (const button of document.querySelectorAll(".units button")) {
    button.setAttribute("aria-pressed", String(button.dataset.units === state.units));
  }
}

/** One animation frame: the playing shot's path grows and its ball moves; once it has played, the views are
 * drawn whole again, with its landing and rest points. */
function tick() {
  if (!playing()) {
    state.ticking = false;
    drawViews();
    return;
  }
  const path = shown(latest());
  if (path.length) {
    for (const { line, ball, project } of live) {
      line.setAttribute("points", points(path, project));
      const [x, y] = project(path[path.length - 1]);
      ball.setAttribute("cx", x.toFixed(1));
      ball.setAttribute("cy", y.toFixed(1));
    }
  }
  requestAnimationFrame(tick);
}

// ---- the bay's conditions (GET/PUT /v1/bay): shown, changed from the form, its units used for every figure ----

/** The form's fields: the bay's value at `path` in SI, shown in the bay's units (to SI and back). */
const BAY_FIELDS = [
  { id: "bay-temperature", path: ["air", "temperature_c"], digits: 1, unit: () => imperial() ? "°F" : "°C",
    show: (c) => imperial() ? c * 9 / 5 + 32 : c, si: (v) => imperial() ? (v - 32) * 5 / 9 : v },
  { id: "bay-altitude", path: ["air", "altitude_m"], digits: 0, unit: () => imperial() ? "ft" : "m",
    show: (m) => imperial() ? m / FEET_M : m, si: (v) => imperial() ? v * FEET_M : v },
  { id: "bay-humidity", path: ["air", "humidity_pct"], digits: 0, unit: () => "%", show: (v) => v, si: (v) => v },
  { id: "bay-wind-speed", path: ["wind", "speed_mps"], digits: 1, unit: speedUnit,
    show: (v) => imperial() ? v / MPH_MPS : v, si: (v) => imperial() ? v * MPH_MPS : v },
  { id: "bay-wind-from", path: ["wind", "from_deg"], digits: 0, unit: () => "°", show: (v) => v, si: (v) => v },
  { id: "bay-stimp", path: ["ground", "stimp_ft"], digits: 1, unit: () => "ft", show: (v) => v, si: (v) => v },
];

function bayValue(bay, [group, name]) { return bay && bay[group] ? bay[group][name] : undefined; }

function bayHeaders() {
  const headers = { "Accept": "application/json" };
  if (state.key) headers["X-API-Key"] = state.key;
  return headers;
}

function bayMessage(kind, text) {
  const message = document.getElementById("bay-message");
  message.dataset.state = kind;
  message.textContent = text;
}

/** The service's words for a refused request: each 422 entry's `message` (field, value and range), or `detail`. */
function refusal(status, answer) {
  const detail = answer && answer.detail;
  if (Array.isArray(detail)) return detail.map((d) => d.message || d.msg).join("; ");
  return typeof detail === "string" ? detail : `refused (${status})`;
}

/** The bay's conditions in a line, in the bay's units. */
function baySummary(bay) {
  const parts = [];
  const air = bay.air || {};
  if (air.density_kg_m3 !== undefined) parts.push(`air ${air.density_kg_m3} kg/m³`);
  else {
    const t = BAY_FIELDS[0], a = BAY_FIELDS[1];
    parts.push(air.temperature_c === undefined ? "15 °C standard air" : `${fixed(t.show(air.temperature_c), 1)}${t.unit()}`);
    if (air.altitude_m !== undefined) parts.push(`${fixed(a.show(air.altitude_m), 0)} ${a.unit()} up`);
    if (air.pressure_hpa !== undefined) parts.push(`${air.pressure_hpa} hPa`);
    if (air.humidity_pct !== undefined) parts.push(`${air.humidity_pct}% humidity`);
  }
  const wind = bay.wind;
  parts.push(wind && wind.speed_mps ? `wind ${speedText(wind.speed_mps)} ${speedUnit()} from ${Math.round(wind.from_deg || 0)}°` : "calm");
  const ground = bay.ground || { surface: "fairway" };
  parts.push(ground.surface.replace("_", " ") + (ground.stimp_ft !== undefined ? `, stimp ${ground.stimp_ft}` : ""));
  return parts.join(" · ");
}

/** The form and the summary from `state.bay`; the fields the operator is editing are left alone unless `all`. */
function showBay(all = true) {
  const bay = state.bay;
  if (!bay) return;
  document.getElementById("bay-summary").textContent = baySummary(bay);
  for (const field of BAY_FIELDS) {
    const input = document.getElementById(field.id);
    document.querySelector(`label[for=${field.id}] .unit`).textContent = field.unit();
    if (!all && input.dataset.dirty) continue;
    const value = bayValue(bay, field.path);
    input.value = typeof value === "number" ? String(Number(field.show(value).toFixed(field.digits))) : "";
    delete input.dataset.dirty;
  }
  const surface = document.getElementById("bay-surface");
  if (all || !surface.dataset.dirty) {
    surface.value = (bay.ground && bay.ground.surface) || "fairway";
    delete surface.dataset.dirty;
  }
  document.getElementById("bay-stimp").disabled = surface.value !== "green";
}

/** Takes the bay the service answered with: its units become the page's. */
/** The bay with its wind speed in m/s, whichever unit it was set in (`speed_mph` over the API): the form and
 * the summary read `speed_mps`. */
function windInMps(bay) {
  const wind = bay.wind;
  if (wind && wind.speed_mps === undefined && wind.speed_mph !== undefined) {
    bay.wind = { ...wind, speed_mps: wind.speed_mph * 0.44704 };
    delete bay.wind.speed_mph;
  }
  return bay;
}

function takeBay(bay, all = true) {
  bay = windInMps(bay);
  state.bay = bay;
  if (bay.units && bay.units !== state.units) {
    state.units = bay.units;
    localStorage.setItem("golfflight-units", state.units);
    render();
  }
  showBay(all);
}

async function loadBay() {
  try {
    const response = await fetch("v1/bay", { headers: bayHeaders(), cache: "no-store" });
    if (response.ok) {
      const editing = document.getElementById("bay-form").contains(document.activeElement);
      takeBay(await response.json(), !editing);
    }
  } catch (error) { /* the stream's status says so */ }
}

/** PUT /v1/bay with `bay`; the service's answer is shown (its message, on a refused value). */
async function putBay(bay) {
  bayMessage("saving", "saving…");
  try {
    const response = await fetch("v1/bay", {
      method: "PUT", headers: { ...bayHeaders(), "Content-Type": "application/json" }, body: JSON.stringify(bay),
    });
    const answer = await response.json().catch(() => null);
    if (!response.ok) {
      bayMessage("refused", refusal(response.status, answer));
      return false;
    }
    takeBay(answer);
    bayMessage("saved", "saved");
    return true;
  } catch (error) {
    bayMessage("refused", "service unreachable");
    return false;
  }
}

/** The bay as the form says: the service's last bay with the fields the operator changed (an emptied one
 * removed), so a value nobody touched goes back exactly as it came, never rounded through the display units. */
function bayFromForm() {
  const bay = structuredClone(state.bay || {});
  for (const field of BAY_FIELDS) {
    const input = document.getElementById(field.id);
    if (!input.dataset.dirty) continue;
    const [group, name] = field.path;
    const text = input.value.trim();
    if (text === "") {
      if (bay[group]) delete bay[group][name];
      continue;
    }
    bay[group] = bay[group] || {};
    const number = Number(text);
    bay[group][name] = Number.isFinite(number) ? Number(field.si(number).toPrecision(12)) : text;
  }
  const surface = document.getElementById("bay-surface").value;
  if (surface !== ((bay.ground && bay.ground.surface) || "fairway")) bay.ground = { ...(bay.ground || {}), surface };
  if (bay.ground && bay.ground.surface !== "green") delete bay.ground.stimp_ft;
  if (bay.wind && bay.wind.speed_mps === undefined) delete bay.wind;  // no speed: calm
  for (const group of ["air", "wind", "ground"]) {
    if (bay[group] && Object.keys(bay[group]).length === 0) delete bay[group];
  }
  return bay;
}

async function setUnits(units) {
  if (state.bay) {
    await putBay({ ...state.bay, units });
    return;
  }
  state.units = units;  // no bay read (yet): this screen only
  localStorage.setItem("golfflight-units", state.units);
  render();
}

// ---- start --------------------------------------------------------------------------------------------------

document.addEventListener("DOMContentLoaded", () => {
  for (const button of document.querySelectorAll(".units button")) {
    button.addEventListener("click", () => setUnits(button.dataset.units));
  }
  document.getElementById("key-form").addEventListener("submit", (event) => {
    event.preventDefault();
    state.key = document.getElementById("key").value;
    sessionStorage.setItem(KEY_STORE, state.key);
    event.target.hidden = true;
    setStatus("connecting", "connecting…");
    follow();
    loadBay();
  });
  const bayForm = document.getElementById("bay-form");
  bayForm.addEventListener("input", (event) => {
    event.target.dataset.dirty = "1";
    document.getElementById("bay-stimp").disabled = document.getElementById("bay-surface").value !== "green";
  });
  bayForm.addEventListener("submit", async (event) => {
    event.preventDefault();
    await putBay(bayFromForm());
  });
  bayForm.addEventListener("reset", (event) => {
    event.preventDefault();
    showBay(true);
    bayMessage("", "");
  });
  render();
  follow();
  loadBay();
  setInterval(loadBay, BAY_POLL_MS);
});
