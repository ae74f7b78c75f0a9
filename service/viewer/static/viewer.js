// golfflight live shot viewer: reads the service's server-sent events (GET /v1/events, one ShotEvent per shot: see
// service/viewer/event.schema.json) and draws each shot from behind the golfer, from the side and from above, with
// its numbers, a shot table and the landing dispersion per club. The bay (GET/PATCH /v1/bay) holds the player's club
// and the units: the page shows them and changes them there, so every screen of the bay and every shot follow.
// Plain JavaScript and SVG, nothing from elsewhere.
"use strict";

const YARD_M = 0.9144;
const MPH_MPS = 0.44704;
const FEET_M = 0.3048;
const KEEP_SHOTS = 50;            // as many as the service keeps
const PLAY_S = 3;                 // the newest shot plays back in real time, but never longer than this
const SVG_NS = "http://www.w3.org/2000/svg";
const KEY_STORE = "golfflight-api-key";
const SOURCES = { "http": "HTTP", "batch": "batch", "gspro-http": "GSPro (HTTP)", "open-connect": "Open Connect" };
const CLUB_COLOURS = ["#ffd23f", "#4cd07d", "#5bc0ff", "#ff8a5b", "#c38bff", "#ff5b9a", "#9be15d", "#f2f2f2"];
const STALL_MS = 45_000;          // the service sends a keep-alive comment every 15 s: silence this long is a dead link
const BAY_POLL_MS = 30_000;       // how often the bay is read again (another screen may change it)

// The behind-the-golfer camera: a perspective camera at the golfer's eye, behind the tee on the target line, looking
// down that line and tilted down just enough to keep the tee in the picture, so the horizon (the target line's
// vanishing point) is in view and a shot reads as an arc receding to its landing. These are the golfer's camera; a
// shot that climbs out of its picture widens it (`behindCamera`).
const CAMERA_HEIGHT_M = 1.6;      // above the tee
const CAMERA_BACK_M = 3;          // behind the tee
const CAMERA_FOV_DEG = 55;        // vertical field of view: from the tee, 28° below level, to 24° above level
const CAMERA_PITCH_DEG = 3.5;     // below level: the tee 6 % of the picture above its bottom, the sky up to 24°
const TEE_Z_M = 0.01;             // the ball on its tee (README: a 1 cm tee)
const FAIRWAY_HALF_M = 20;
const FAR_GROUND_M = 5000;        // where the fairway's edges are drawn to: a pixel or two short of the horizon
const LABEL_GAP_PX = 14;          // a distance label closer than this to the one kept before it is left out
const APEX_MARGIN = 0.07;         // the highest point of any shot shown stays this part of the picture below its top
const MAX_FOV_DEG = 90;           // wider than this the picture bends too much: the camera steps back instead
const SIDE_MARGIN_PX = 4;         // every shot shown stays this far inside the behind view's left and right edges
const PIN_STORE = "golfflight-pin-m";  // the pin's distance down the target line, metres ("" or absent: no pin)
const FLAG_PX = 16;               // the pin's flagstick as drawn, pixels: a symbol, readable at any distance

// Every SVG's viewBox is its rendered size in CSS pixels (`frame`), so the labels' font sizes (viewer.css) are the
// sizes on screen at any width, and margins are worked out from the labels' measured widths.

const state = {
  shots: [],                       // newest last: {event, club}, club the GSPro code of the event's player, or ""
  units: localStorage.getItem("golfflight-units") || "imperial",  // the bay's `units` once read (GET /v1/bay)
  bay: null,                       // the bay as the service last gave it
  key: initialKey(),
  lastId: null,
  play: null,                      // {id, started, speed, end}
  ticking: false,
};

/** The newest shot's polyline and ball in each view while it plays: all that an animation frame redraws. */
const live = [];

// ---- units: SI inside; yards and mph only on screen, by the bay's units --------------------------------------

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

// ---- clubs: GSPro's codes, named as the page's club menu names them (filled in from contract.clubs.GSPRO_CLUBS) --

/** GSPro club code -> its name, from the club menu's options. */
const CLUB_NAMES = new Map();

function clubName(code) { return CLUB_NAMES.get(code) || code || "no club"; }

/** The club a shot was hit with: its event's player (the bay's player when it was flown), "" for none. */
function clubOf(event) { return event.player && event.player.club ? event.player.club : ""; }

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

/** The headers of a request to the service: JSON, and the API key when there is one. */
function keyHeaders(accept = "application/json") {
  const headers = { "Accept": accept };
  if (state.key) headers["X-API-Key"] = state.key;
  return headers;
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
      const headers = keyHeaders("text/event-stream");
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
  else if (kind === "session" && data.length) onSession(JSON.parse(data.join("\n")));  // session.js
}

/** A shot from the stream. Its club is its event's (the bay's player when it was flown, kept by the service, so a
 * reloaded page tags it alike); a shot hit with another club than the menu shows means the bay's player changed:
 * the bay is read again. */
function addShot(event) {
  const seen = state.shots.some((s) => s.event.id === event.id && s.event.received_unix_s === event.received_unix_s);
  if (seen) return;
  const club = clubOf(event);
  state.shots.push({ event, club });
  if (state.shots.length > KEEP_SHOTS) state.shots.shift();
  const points = event.flight.trajectory || (event.flight.trajectory = []);
  const end = points.length ? points[points.length - 1].t_s : 0;
  state.play = { id: event.id, started: performance.now(), speed: Math.max(1, end / PLAY_S), end };
  render();
  if (!state.ticking) {
    state.ticking = true;
    requestAnimationFrame(tick);
  }
  if (club && state.bay && state.bay.player && club !== state.bay.player.club) readBaySoon();
  readSummarySoon();  // session.js: the session's summary with this shot
}

let bayRead = null;

/** GET /v1/bay once, shortly (a burst of kept shots on a reload asks once). */
function readBaySoon() {
  if (bayRead === null) bayRead = setTimeout(() => { bayRead = null; loadBay(); }, 300);
}

// ---- the pin: a flag on the target line at a distance the golfer sets (the header's "Pin" field), kept in this
// browser's localStorage in metres, drawn in every view, and the last shot's rest measured to it -------------

/** The pin's distance down the target line, metres, or null when none is set. */
function pinMetres() {
  const stored = Number(localStorage.getItem(PIN_STORE) || NaN);
  return Number.isFinite(stored) && stored > 0 ? stored : null;
}

/** The pin field typed in (the page's units): a distance from 1 to 1,000 sets the pin, an empty field takes it
 * away; anything else puts the field back as it was. */
function setPin(text) {
  const value = Number(text.trim());
  if (text.trim() === "") localStorage.setItem(PIN_STORE, "");
  else if (Number.isFinite(value) && value >= 1 && value <= 1000) {
    localStorage.setItem(PIN_STORE, String(value * (imperial() ? YARD_M : 1)));
  }
  showPin(true);
  render();
}

/** The pin field and its unit in the page's units; a field being typed in is left alone unless `always`. */
function showPin(always = false) {
  const input = document.getElementById("pin");
  document.getElementById("pin-unit").textContent = distUnit();
  if (!always && document.activeElement === input && input.dataset.units === state.units) return;
  const pin = pinMetres();
  input.value = pin === null ? "" : String(Number((pin / (imperial() ? YARD_M : 1)).toFixed(1)));
  input.dataset.units = state.units;
}

/** The last shot's "To pin" tile: how far its rest lies from the pin (its landing for a shot without a rest);
 * hidden while no pin is set. */
function showToPin(shot) {
  const tile = document.getElementById("n-to-pin");
  const pin = pinMetres();
  tile.parentElement.hidden = pin === null;
  const flight = shot && shot.event.flight;
  const end = flight && (flight.rest || flight.landing);
  const metres = pin === null || !end ? null : Math.hypot(end.x_m, end.y_m - pin);
  setNumber("n-to-pin", fixed(metres === null ? null : metres / (imperial() ? YARD_M : 1)), distUnit());
}

/** The pin as a symbol standing on (x, y), FLAG_PX high whatever the view's scale: a hole, a stick, a flag. */
function drawFlag(svg, x, y, metres) {
  const group = el(svg, "g", { class: "pin", "data-m": metres.toFixed(2) });
  el(group, "ellipse", { class: "pin-hole", cx: x, cy: y, rx: 3, ry: 1.5 });
  el(group, "line", { class: "pin-stick", x1: x, y1: y, x2: x, y2: y - FLAG_PX });
  el(group, "polygon", { class: "pin-flag", points: `${x},${y - FLAG_PX} ${x + 9},${y - FLAG_PX + 3.5} ${x},${y - FLAG_PX + 7}` });
  return group;
}

/** The pin's label, "pin 150 yd", beside its flag: right of it, or left of it where the right has no room; left out
 * (null) where neither has room among the labels kept. */
function pinLabel(svg, kept, W, H, x, y, metres) {
  const text = `pin ${unitLabel(metres)}`;
  const at = { class: "label scale pin-label", y: y - FLAG_PX + 7 };
  return placeLabel(svg, kept, W, H, { ...at, x: x + 12 }, text)
    || placeLabel(svg, kept, W, H, { ...at, x: x - 4, "text-anchor": "end" }, text);
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

/** The newest shot that flew (a putt rolls from the start: it has no apex to read heights at), or null. */
function latestFlight() {
  for (let i = state.shots.length - 1; i >= 0; i--) {
    const shot = state.shots[i];
    if (!shot.event.putt && shot.event.flight.trajectory.length) return shot;
  }
  return null;
}

/** A shot's number on the screens: its number in its session (#1 for the session's first), or, from a service
 * that does not send one, its event id. */
function shotNumber(shot) { return shot.event.session_shot ?? shot.event.id; }

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

/** A ground's elevation relative to the tee, metres (`elevation_m`, or `elevation_ft` as the API takes it). */
function elevationOf(ground) {
  if (!ground) return 0;
  if (typeof ground.elevation_m === "number") return ground.elevation_m;
  if (typeof ground.elevation_ft === "number") return ground.elevation_ft * FEET_M;
  return 0;
}

/** The ground the views draw: the bay's (what the next shot lands on), or the newest shot's before the bay is read. */
function groundElevation() {
  if (state.bay) return elevationOf(state.bay.ground);
  const newest = latest();
  return newest ? elevationOf(newest.event.ground) : 0;
}

/** The scene's size in metres: downrange to a round number of the unit shown (the pin included), height (from the
 * lowest point: a green below the tee), lateral spread, and the ground's elevation. */
function extent() {
  const step = 50 * (imperial() ? YARD_M : 1);
  const ground = groundElevation();
  let far = pinMetres() || 0, high = 0, low = Math.min(0, ground), wide = 0;
  for (const shot of state.shots) {
    for (const p of shot.event.flight.trajectory) {
      far = Math.max(far, p.y_m); high = Math.max(high, p.z_m); low = Math.min(low, p.z_m); wide = Math.max(wide, Math.abs(p.x_m));
    }
  }
  return {
    step, ground, low,
    far: Math.max(2, Math.ceil((far * 1.05) / step)) * step,
    high: Math.max(low + 10, high + (high - low) * 0.15),
    wide: Math.max(15, wide * 1.2),
  };
}

/** A round step for a scale in the unit shown (1, 2 or 5 times a power of ten yards or metres), in metres: the
 * smallest at least `least` metres. */
function niceStep(least) {
  const unit = imperial() ? YARD_M : 1;
  for (let power = 1; power < 1e6; power *= 10) {
    for (const m of [1, 2, 5]) if (m * power * unit >= least) return m * power * unit;
  }
  return 1e6 * unit;  // (never a sensible scale: no tick of it is drawn)
}

/** A lateral distance as a golfer reads it: "10 yd L", "10 yd R", "0" on the target line. */
function lateralLabel(metres) {
  const size = Math.round(Math.abs(metres) / (imperial() ? YARD_M : 1));
  return size === 0 ? "0" : `${size} ${distUnit()} ${metres < 0 ? "L" : "R"}`;
}

function points(list, project) {
  return list.map((p) => project(p).map((v) => v.toFixed(1)).join(",")).join(" ");
}

/** A whole path's points in a view, worked out once per shot and kept while the view's projection (`scene`) holds. */
function pathPoints(shot, svg, scene, project) {
  const kept = (shot.paths ||= {})[svg.id];
  if (kept && kept.scene === scene) return kept.text;
  const text = points(shot.event.flight.trajectory, project);
  shot.paths[svg.id] = { scene, text };
  return text;
}

/** Where a flight came down: the trajectory passes exactly through its landing point, at the ground's height there. */
function landingPoint(flight) {
  const { x_m, y_m } = flight.landing;
  let best = null, bestGap = Infinity;
  for (const p of flight.trajectory) {
    const gap = (p.x_m - x_m) ** 2 + (p.y_m - y_m) ** 2;
    if (gap < bestGap) { best = p; bestGap = gap; }
  }
  return { x_m, y_m, z_m: best ? best.z_m : 0 };
}

/** Every shot as a polyline through exactly its trajectory's points in one view (`scene`: its projection, for the
 * kept points), the newest highlighted and flown as it plays; its landing and rest points once it has come down. */
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
  if (!newest || !newest.event.flight.trajectory.length) return;  // nothing to draw: no path came with it
  const flight = newest.event.flight;
  if (moving) {
    const path = shown(newest);
    const [x, y] = project(path[path.length - 1] || flight.trajectory[0]);
    const ball = el(svg, "circle", { class: "ball", cx: x, cy: y, r: 4 });
    live.push({ line: newestLine, ball, project });
    return;
  }
  newestLine.dataset.done = "1";
  const [lx, ly] = project(landingPoint(flight));
  el(svg, "circle", { class: "landing", cx: lx, cy: ly, r: 6 });
  if (flight.rest) {
    const [rx, ry] = project(flight.trajectory[flight.trajectory.length - 1]);  // it ends exactly at rest
    el(svg, "circle", { class: "rest", cx: rx, cy: ry, r: 4 });
  }
}

function unitLabel(metres) { return `${Math.round(metres / (imperial() ? YARD_M : 1))} ${distUnit()}`; }

/** Sets an SVG's viewBox to the size it is drawn at, in CSS pixels (height `aspect` times the width, at least
 * `minHeight`), so that one unit is one pixel on screen: [width, height]. */
function frame(svg, aspect, minHeight = 0) {
  const W = Math.round(svg.getBoundingClientRect().width) || 800;
  const H = Math.max(Math.round(W * aspect), minHeight);
  svg.setAttribute("viewBox", `0 0 ${W} ${H}`);
  return [W, H];
}

/** A label's width as it will be drawn in `svg` (class `cls`), measured. */
function textWidth(svg, text, cls = "label") {
  const probe = el(svg, "text", { class: cls, x: 0, y: 0 }, text);
  const width = probe.getComputedTextLength() || text.length * 7;
  probe.remove();
  return width;
}

function boxesApart(a, b, gap = 2) {
  return a.x + a.width + gap <= b.x || b.x + b.width + gap <= a.x || a.y + a.height + gap <= b.y || b.y + b.height + gap <= a.y;
}

/** A label drawn unless it would overlap one already kept (`kept`: their boxes) or leave the picture (W x H):
 * the text element, or null when it was left out. */
function placeLabel(svg, kept, W, H, attrs, text) {
  const label = el(svg, "text", attrs, text);
  const box = label.getBBox();
  const inside = box.x >= 0 && box.y >= 0 && box.x + box.width <= W && box.y + box.height <= H;
  if (!inside || !kept.every((other) => boxesApart(box, other))) {
    label.remove();
    return null;
  }
  kept.push(box);
  return label;
}

/** From behind the golfer: a perspective camera CAMERA_HEIGHT_M above the tee and CAMERA_BACK_M behind it on the
 * target line, CAMERA_FOV_DEG of vertical view, looking down the line tilted CAMERA_PITCH_DEG down: the tee at the
 * bottom centre, the target line straight up the middle to its vanishing point on the horizon, so a straight shot
 * (direction 0, spin axis 0, no crosswind) stays on it, and every shot an arc receding to where it lands. The ground
 * is a plane at the bay's elevation (the tee at 0); distance lines cross it every 50 yd (or 50 m), receding to the
 * horizon; a line's label, at the picture's right edge, is left out when it would come closer than LABEL_GAP_PX to the
 * one kept before it. A shot that would leave the golfer's picture widens the camera (`behindCamera`), and level
 * lines at the last shot's apex give the heights (`drawBehindHeights`). What was drawn is kept on
 * `window.golfflightViewer.behind`. */
function drawBehind(svg, box) {
  svg.replaceChildren();
  const [W, H] = frame(svg, 1);
  const camera = behindCamera(W, H);
  const project = behindProjection(W, H, camera);
  const horizon = H / 2 - camera.focal * Math.tan(camera.pitch);
  const ground = box.ground;
  const on = (x, y) => ({ x_m: x, y_m: y, z_m: ground });
  const defs = el(svg, "defs");
  const sky = el(defs, "linearGradient", { id: "sky", x1: 0, y1: 0, x2: 0, y2: 1 });
  el(sky, "stop", { offset: "0", "stop-color": "#0f2740" });
  el(sky, "stop", { offset: "1", "stop-color": "#3d6d8f" });
  const skyline = Math.min(Math.max(horizon, 0), H);  // a widened camera may tilt the horizon out of the picture
  el(svg, "rect", { class: "sky", x: 0, y: 0, width: W, height: skyline });
  el(svg, "rect", { class: "rough", x: 0, y: skyline, width: W, height: H - skyline });
  const near = -Math.min(camera.back, CAMERA_BACK_M) / 2;  // the fairway from halfway between the golfer and the tee
  const fairway = [on(-FAIRWAY_HALF_M, near), on(FAIRWAY_HALF_M, near), on(FAIRWAY_HALF_M, FAR_GROUND_M), on(-FAIRWAY_HALF_M, FAR_GROUND_M)];
  el(svg, "polygon", { class: "fairway", points: points(fairway, project) });
  for (let x = -2 * FAIRWAY_HALF_M; x <= 2 * FAIRWAY_HALF_M; x += FAIRWAY_HALF_M / 2) {  // receding to the horizon
    if (x === 0) continue;
    const [x1, y1] = project(on(x, near)), [x2, y2] = project(on(x, FAR_GROUND_M));
    el(svg, "line", { class: Math.abs(x) === FAIRWAY_HALF_M ? "lane edge" : "lane", x1, y1, x2, y2 });
  }
  el(svg, "line", { class: "horizon", x1: 0, y1: horizon, x2: W, y2: horizon });
  const kept = [], labels = [];
  let lastY = Infinity;
  for (let y = box.step; y <= box.far + 1e-6; y += box.step) {
    const [, ly] = project(on(0, y));  // a line across the ground at y: level across the picture
    el(svg, "line", { class: "marker-line", x1: 0, y1: ly, x2: W, y2: ly, "data-m": y.toFixed(2) });
    if (lastY - ly < LABEL_GAP_PX) continue;
    const label = placeLabel(svg, kept, W, H, { class: "label distance", x: W - 6, y: ly - 3, "text-anchor": "end" }, unitLabel(y));
    if (!label) continue;
    lastY = ly;
    const b = label.getBBox();
    labels.push({ text: label.textContent, line_y: ly, box: [b.x, b.y, b.width, b.height] });
  }
  const [tx, ty] = project({ x_m: 0, y_m: 0, z_m: TEE_Z_M });
  const [gx, gy] = project(on(0, 0));
  el(svg, "line", { class: "target-line", x1: gx, y1: gy, x2: W / 2, y2: horizon });
  el(svg, "circle", { class: "tee", cx: tx, cy: ty, r: 3 });
  const heights = drawBehindHeights(svg, project, W, H, kept);
  const pin = pinMetres();
  if (pin !== null) {
    const [px, py] = project(on(0, pin));
    drawFlag(svg, px, py, pin);
    pinLabel(svg, kept, W, H, px, py, pin);
  }
  drawShots(svg, project, `${W} ${H} ${ground} ${camera.focal} ${camera.pitch} ${camera.back}`);
  (window.golfflightViewer ||= {}).behind = {
    width: W, height: H, tee: [tx, ty], vanishing: [W / 2, horizon], labels, heights, ground_m: ground,
    camera: { height_m: CAMERA_HEIGHT_M, back_m: camera.back, fov_deg: camera.fov_deg, pitch_deg: camera.pitch_deg },
  };
}

/** The behind view's projection for `camera` ({back, pitch, focal}: metres behind the tee, radians down, pixels):
 * a point (x_m, y_m, z_m) to its [x, y] in a W x H picture. Its y depends on the point's distance and height only,
 * so a level line across the target line is level in the picture. */
function behindProjection(W, H, camera) {
  const cos = Math.cos(camera.pitch), sin = Math.sin(camera.pitch);
  return (p) => {
    const ahead = p.y_m + camera.back, up = p.z_m - CAMERA_HEIGHT_M;
    const depth = Math.max(ahead * cos - up * sin, 0.1);  // along the camera's axis
    return [W / 2 + (camera.focal * p.x_m) / depth, H / 2 - (camera.focal * (ahead * sin + up * cos)) / depth];
  };
}

/** A camera `back` metres behind the tee with the focal length `focal` (pixels), or null where none holds the shots
 * shown: of the tilts that keep the steepest point they reach (`high`: its angle above level from there, radians)
 * APEX_MARGIN of the picture below its top and the lowest (`low`, the tee's as a rule) no lower than `bottom`, the
 * one nearest the golfer's CAMERA_PITCH_DEG. {back, pitch, focal, fov_deg, pitch_deg}. */
function framedCamera(H, back, focal, [low, high], bottom) {
  const mostDown = Math.atan((H / 2 - H * APEX_MARGIN - 0.5) / focal) - high;
  const mostUp = -Math.atan((bottom - H / 2) / focal) - low;
  if (mostUp > mostDown) return null;
  const pitch = Math.min(mostDown, Math.max(mostUp, (CAMERA_PITCH_DEG * Math.PI) / 180));
  return { back, pitch, focal, fov_deg: (Math.atan(H / 2 / focal) * 360) / Math.PI, pitch_deg: (pitch * 180) / Math.PI };
}

/** The lowest and the steepest angles above level, radians, at which a camera `back` metres behind the tee sees the
 * tee and the shots shown. */
function angleRange(back) {
  let low = Math.atan2(TEE_Z_M - CAMERA_HEIGHT_M, back), high = low;
  for (const shot of state.shots) {
    for (const p of shot.event.flight.trajectory) {
      const angle = Math.atan2(p.z_m - CAMERA_HEIGHT_M, p.y_m + back);
      low = Math.min(low, angle);
      high = Math.max(high, angle);
    }
  }
  return [low, high];
}

/** Whether every point of every shot shown lies inside the behind view through `camera`: APEX_MARGIN of the height
 * below its top, no lower than `bottom` (pixels down), SIDE_MARGIN_PX inside its sides, and in front of the camera. */
function behindFits(W, H, camera, bottom = H) {
  const project = behindProjection(W, H, camera);
  const cos = Math.cos(camera.pitch), sin = Math.sin(camera.pitch);
  for (const shot of state.shots) {
    for (const p of shot.event.flight.trajectory) {
      if ((p.y_m + camera.back) * cos - (p.z_m - CAMERA_HEIGHT_M) * sin < 0.5) return false;
      const [x, y] = project(p);
      if (y < H * APEX_MARGIN - 1 || y > bottom || Math.abs(x - W / 2) > W / 2 - SIDE_MARGIN_PX) return false;
    }
  }
  return true;
}

/** The behind view's camera for the shots shown: the golfer's (CAMERA_*) while every shot fits its picture with
 * APEX_MARGIN of sky above the highest; otherwise the least change that holds them all with the tee no lower than
 * the golfer's camera shows it: a wider field of view (up to MAX_FOV_DEG), tilted as little from the golfer's as
 * that allows (`framedCamera`), and beyond that the camera stepping back along the target line (a shot launched
 * very steeply, or sent far off line). A high wedge (85 mph, 30°, 10,000 rpm) climbs to 25° above the golfer's
 * eye, above the 20.6° the golfer's camera holds under its margin: 59° of view, tilted 1.3° down, holds it. */
function behindCamera(W, H) {
  const key = `${W} ${H} ${state.shots.map((s) => `${s.event.id}@${s.event.received_unix_s}`).join(" ")}`;
  if (behindCamera.kept && behindCamera.kept.key === key) return behindCamera.kept.camera;  // the same shots
  const camera = fitBehindCamera(W, H);
  behindCamera.kept = { key, camera };
  return camera;
}

/** `behindCamera`, worked out: the golfer's camera, or the search for the least change that holds every shot. */
function fitBehindCamera(W, H) {
  const focal = H / 2 / Math.tan((CAMERA_FOV_DEG * Math.PI) / 360);
  const golfer = { back: CAMERA_BACK_M, pitch: (CAMERA_PITCH_DEG * Math.PI) / 180, focal, fov_deg: CAMERA_FOV_DEG, pitch_deg: CAMERA_PITCH_DEG };
  if (behindFits(W, H, golfer)) return golfer;
  const bottom = behindProjection(W, H, golfer)({ x_m: 0, y_m: 0, z_m: TEE_Z_M })[1];  // where the golfer sees the tee
  const widest = H / 2 / Math.tan((MAX_FOV_DEG * Math.PI) / 360);
  const fits = (camera) => camera !== null && behindFits(W, H, camera, bottom + 2);
  let back = CAMERA_BACK_M;
  for (; back < 200; back *= 2) {
    const range = angleRange(back);
    if (!fits(framedCamera(H, back, widest, range, bottom))) continue;
    let good = widest, bad = focal;  // the longest focal length that fits, found by halving (to 1/10,000 of H)
    for (let i = 0; i < 14; i++) {
      const mid = (good + bad) / 2;
      if (fits(framedCamera(H, back, mid, range, bottom))) good = mid;
      else bad = mid;
    }
    return framedCamera(H, back, good, range, bottom);
  }
  // nothing sensible holds them (a ball launched nearly straight up): the widest, farthest camera, level
  return { back, pitch: 0, focal: widest, fov_deg: MAX_FOV_DEG, pitch_deg: 0 };
}

/** Heights in the behind view: level lines every round step (10 yd for a wedge or a driver) up to the highest shot
 * shown, standing in the upright plane across the target line at the last shot's apex, so that its apex (marked
 * once it has flown) reads off them; labelled at the left edge under a caption saying how far out that plane is:
 * [{text, line_y, box}]. */
function drawBehindHeights(svg, project, W, H, kept) {
  const newest = latestFlight();
  if (!newest) return [];
  let apex = newest.event.flight.trajectory[0], high = 0;
  for (const p of newest.event.flight.trajectory) if (p.z_m > apex.z_m) apex = p;
  for (const shot of state.shots) for (const p of shot.event.flight.trajectory) high = Math.max(high, p.z_m);
  const step = niceStep(high / 5);  // four or five levels at most
  const levels = [];
  for (let z = step; z <= high + 1e-6; z += step) levels.push([z, project({ x_m: 0, y_m: apex.y_m, z_m: z })[1]]);
  if (!levels.length) return [];
  placeLabel(svg, kept, W, H, { class: "label scale height-caption", x: 6, y: 16 }, `heights ${unitLabel(apex.y_m)} out`);
  const labels = [];
  let lastY = Infinity;
  for (const [z, y] of levels) {
    el(svg, "line", { class: "height-line", x1: 0, y1: y, x2: W, y2: y, "data-m": z.toFixed(2) });
    if (lastY - y < LABEL_GAP_PX) continue;
    const label = placeLabel(svg, kept, W, H, { class: "label scale height", x: 6, y: y - 3 }, unitLabel(z));
    if (!label) continue;
    lastY = y;
    const b = label.getBBox();
    labels.push({ text: label.textContent, line_y: y, box: [b.x, b.y, b.width, b.height] });
  }
  if (!playing()) {
    const [ax, ay] = project(apex);
    el(svg, "line", { class: "apex-mark", x1: ax - 7, y1: ay, x2: ax + 7, y2: ay });
  }
  return labels;
}

/** From the side: downrange to the right, height up, one scale for both; the tee at 0 and the ground at its
 * elevation. The margins are the labels' measured widths, and the distance lines are labelled every one, every
 * other one, ... as their labels' widths allow, so nothing is cut or crammed at any width. */
function drawSide(svg, box) {
  svg.replaceChildren();
  const [W, H] = frame(svg, 0.3125, 150);
  const heightStep = imperial() ? 10 * YARD_M : 10;
  const heights = [];
  for (let k = Math.ceil(box.low / heightStep); k * heightStep <= box.high; k++) if (k !== 0) heights.push(k * heightStep);
  const { lines, texts, widths } = alongTicks(svg, box);
  const heightWidth = Math.max(0, ...heights.map((z) => textWidth(svg, unitLabel(z))));
  const left = Math.max(heightWidth + 10, widths[0] / 2 + 4), right = widths[widths.length - 1] / 2 + 6;
  const top = 10, bottom = 24;
  const scale = Math.min((W - left - right) / box.far, (H - top - bottom) / (box.high - box.low));
  const base = H - bottom + box.low * scale;  // z = 0
  const project = (p) => [left + p.y_m * scale, base - p.z_m * scale];
  const kept = [];
  drawAlong(svg, kept, [W, H], { lines, texts, widths }, { left, scale, top: top - 2, bottom: H - bottom, step: box.step });
  for (const z of heights) {
    const y = base - z * scale;
    el(svg, "line", { class: "grid faint", x1: left, y1: y, x2: W - right, y2: y });
    placeLabel(svg, kept, W, H, { class: "label height", x: left - 6, y: y + 4, "text-anchor": "end" }, unitLabel(z));
  }
  const groundY = base - box.ground * scale;
  el(svg, "line", { class: "ground-line", x1: left, y1: groundY, x2: W - right, y2: groundY });
  if (Math.abs(box.ground) * scale >= 1) el(svg, "line", { class: "ground-line tee-box", x1: left - 4, y1: base, x2: left + 6, y2: base });
  const pin = pinMetres();
  if (pin !== null) drawFlag(svg, ...project({ x_m: 0, y_m: pin, z_m: box.ground }), pin);
  drawShots(svg, project, `${W} ${H} ${scale} ${base}`);
}

/** The distance lines downrange (every box.step from the tee to box.far) with their labels and the labels'
 * measured widths, for the side and top views' margins. */
function alongTicks(svg, box) {
  const lines = [];
  for (let y = 0; y <= box.far + 1e-6; y += box.step) lines.push(y);
  const texts = lines.map(unitLabel);
  return { lines, texts, widths: texts.map((text) => textWidth(svg, text)) };
}

/** The distance lines as upright grid lines from `top` to `bottom` at left + y * scale, labelled under the picture
 * every one, every other one, ... as their labels' widths allow: never crammed, never cut. */
function drawAlong(svg, kept, [W, H], { lines, texts, widths }, { left, scale, top, bottom, step }) {
  const stride = Math.max(1, Math.ceil((Math.max(...widths) + 10) / (step * scale)));
  lines.forEach((y, n) => {
    const x = left + y * scale;
    el(svg, "line", { class: "grid", x1: x, y1: top, x2: x, y2: bottom, "data-m": y.toFixed(2) });
    if (n % stride === 0) placeLabel(svg, kept, W, H, { class: "label along", x, y: H - 7, "text-anchor": "middle" }, texts[n]);
  });
}

/** From above: downrange to the right, the golfer's right downwards, one scale for both. Distances are labelled
 * under the picture as in the side view, and lateral lines every round step either side of the target line
 * ("10 yd L" above it, "10 yd R" below) at its left; the pin stands on the target line with its distance. */
function drawTop(svg, box) {
  svg.replaceChildren();
  const [W, H] = frame(svg, 0.3125, 150);
  const along = alongTicks(svg, box);
  const sideWidth = textWidth(svg, lateralLabel(-100 * (imperial() ? YARD_M : 1)));  // the widest lateral label
  const left = Math.max(sideWidth + 10, along.widths[0] / 2 + 4), right = along.widths[along.widths.length - 1] / 2 + 6;
  const top = 8, bottom = H - 22, mid = (top + bottom) / 2;
  const scale = Math.min((W - left - right) / box.far, (bottom - top) / (2 * box.wide));
  const project = (p) => [left + p.y_m * scale, mid + p.x_m * scale];
  const fairwayTop = Math.max(top, mid - FAIRWAY_HALF_M * scale), fairwayBottom = Math.min(bottom, mid + FAIRWAY_HALF_M * scale);
  el(svg, "rect", { class: "fairway", x: left, y: fairwayTop, width: box.far * scale, height: fairwayBottom - fairwayTop, opacity: 0.5 });
  const kept = [];
  drawAlong(svg, kept, [W, H], along, { left, scale, top, bottom, step: box.step });
  const step = niceStep((LABEL_GAP_PX + 4) / scale);  // lateral lines at least a label's height and a gap apart
  for (let x = step; x * scale <= mid - top + 1e-6; x += step) {
    for (const signed of [-x, x]) {
      const y = mid + signed * scale;
      el(svg, "line", { class: "grid faint lateral", x1: left, y1: y, x2: W - right, y2: y, "data-m": signed.toFixed(2) });
      placeLabel(svg, kept, W, H, { class: "label lateral", x: left - 6, y: y + 4, "text-anchor": "end" }, lateralLabel(signed));
    }
  }
  el(svg, "line", { class: "target-line", x1: left, y1: mid, x2: W - right, y2: mid });
  const pin = pinMetres();
  if (pin !== null) {
    const [px, py] = project({ x_m: 0, y_m: pin, z_m: 0 });
    drawFlag(svg, px, py, pin);
    pinLabel(svg, kept, W, H, px, py, pin);
  }
  drawShots(svg, project, `${W} ${H} ${scale} ${mid}`);
}

/** The dispersion view's lateral half-width and the step of its lateral scale, metres, for `inner` pixels across:
 * the smallest round step whose labels stand apart, the half-width widened to that step where the shots spread
 * less, so that a labelled line stands either side of the target line (none where even that cannot be). */
function dispersionLateral(svg, wide, inner) {
  let step = niceStep(0);
  for (let tries = 0; tries < 40; tries++, step = niceStep(step * 1.01)) {
    const half = Math.max(wide, step);
    if ((step * inner) / (2 * half) >= textWidth(svg, lateralLabel(-half)) + 10) return { wide: half, step };
  }
  return { wide, step: Infinity };
}

/** The dispersion view's scales: distance lines across it labelled at its left, lateral lines along it every round
 * step either side of the target line labelled under it ("10 yd L", "0", "10 yd R"), the target line and the pin
 * with its distance. Returns the labels' boxes kept (`placeLabel`). */
function drawDispersionAxes(svg, { S, pad, wide, step, lines, project }) {
  const kept = [];
  for (const y of lines) {
    const [, py] = project(0, y);
    el(svg, "line", { class: "grid", x1: pad, y1: py, x2: S - pad, y2: py, "data-m": y.toFixed(2) });
    placeLabel(svg, kept, S, S, { class: "label along", x: pad - 6, y: py + 4, "text-anchor": "end" }, unitLabel(y));
  }
  const bottom = S - pad;
  placeLabel(svg, kept, S, S, { class: "label lateral", x: S / 2, y: bottom + 21, "text-anchor": "middle" }, lateralLabel(0));
  for (let x = step; x <= wide + 1e-6; x += step) {
    for (const signed of [-x, x]) {
      const [px] = project(signed, 0);
      el(svg, "line", { class: "grid faint lateral", x1: px, y1: pad / 2, x2: px, y2: bottom + 4, "data-m": signed.toFixed(2) });
      placeLabel(svg, kept, S, S, { class: "label lateral", x: px, y: bottom + 21, "text-anchor": "middle" }, lateralLabel(signed));
    }
  }
  el(svg, "line", { class: "target-line", x1: S / 2, y1: pad / 2, x2: S / 2, y2: bottom });
  const pin = pinMetres();
  if (pin !== null) {
    const [px, py] = project(0, pin);
    drawFlag(svg, px, py, pin);
    pinLabel(svg, kept, S, S, px, py, pin);
  }
  return kept;
}

/** Landing points (filled) and rest points (rings) per club, seen from behind; a putt has its rest point only. */
function drawDispersion(svg, box) {
  svg.replaceChildren();
  const [S] = frame(svg, 1);
  const lines = [];
  for (let y = 0; y <= box.far + 1e-6; y += box.step) lines.push(y);
  const pad = Math.max(24, ...lines.map((y) => textWidth(svg, unitLabel(y)) + 10));
  const clubs = [...new Set(state.shots.map((s) => s.club))];
  const colour = (club) => CLUB_COLOURS[clubs.indexOf(club) % CLUB_COLOURS.length];
  const { wide, step } = dispersionLateral(svg, Math.max(box.wide, box.far / 8), S - 2 * pad);
  const sx = (S - 2 * pad) / (2 * wide), sy = (S - 2 * pad) / box.far;
  const project = (x, y) => [S / 2 + x * sx, S - pad - y * sy];
  const kept = drawDispersionAxes(svg, { S, pad, wide, step, lines, project });
  // rest rings first and in the club's colour (CSSOM: a stroke attribute loses to the .dot rule, which drew them
  // dark over the landing dots as half discs), then the landing dots, whole, on top
  for (const shot of state.shots) {
    const flight = shot.event.flight;
    if (!flight.rest) continue;
    const [rx, ry] = project(flight.rest.x_m, flight.rest.y_m);
    el(svg, "circle", { class: "dot rest-dot", cx: rx, cy: ry, r: 5 }).style.stroke = colour(shot.club);
  }
  for (const shot of state.shots) {
    if (shot.event.putt) continue;
    const flight = shot.event.flight;
    const [x, y] = project(flight.landing.x_m, flight.landing.y_m);
    el(svg, "circle", { class: "dot", cx: x, cy: y, r: 5, fill: colour(shot.club), "data-shot": shot.event.id });
  }
  drawSummary(svg, project, colour);  // session.js: the session's ellipses per club, and its summary table
  const legend = document.getElementById("legend");
  legend.replaceChildren();
  for (const club of clubs) {
    const group = state.shots.filter((s) => s.club === club);
    const putts = group.every((s) => s.event.putt);
    const figure = putts ? "total" : "carry";
    const values = group.map((s) => distance(s.event.flight, figure)).filter((v) => v !== null);
    const mean = values.length ? values.reduce((a, b) => a + b, 0) / values.length : null;
    const item = document.createElement("li");
    item.style.setProperty("--swatch", colour(club));
    const count = `${group.length} ${putts ? "putt" : "shot"}${group.length > 1 ? "s" : ""}`;
    item.textContent = `${clubName(club)}: ${count}, ${figure} ${fixed(mean)} ${distUnit()} on average`;
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

/** The connector's ClubData (GSPro Open Connect), in the order a launch monitor shows them: [field, name, kind].
 * Speeds come in mph, as GSPro's ball speed does (m/s on a metric screen), angles in degrees; the face impact comes
 * with no unit in Open Connect and is shown as sent. */
const CLUB_DATA = [
  ["Speed", "Club speed", "speed"],
  ["SpeedAtImpact", "Speed at impact", "speed"],
  ["AngleOfAttack", "Attack angle", "deg"],
  ["Path", "Club path", "deg"],
  ["FaceToTarget", "Face to target", "deg"],
  ["Loft", "Dynamic loft", "deg"],
  ["Lie", "Lie", "deg"],
  ["ClosureRate", "Closure rate", "deg/s"],
  ["HorizontalFaceImpact", "Impact across the face", "raw"],
  ["VerticalFaceImpact", "Impact up the face", "raw"],
];

/** The last shot's ClubData as tiles (those it has, in CLUB_DATA's order, then any other field as sent); hidden
 * when the shot came without any. */
function showClubData(clubData) {
  const list = document.getElementById("club-numbers");
  const title = document.getElementById("club-numbers-title");
  list.replaceChildren();
  const entries = clubData ? Object.entries(clubData).filter(([, v]) => v !== null && v !== undefined) : [];
  const known = new Map(CLUB_DATA.map(([field, name, kind]) => [field, { name, kind }]));
  entries.sort(([a], [b]) => (known.has(a) ? CLUB_DATA.findIndex(([f]) => f === a) : 99) - (known.has(b) ? CLUB_DATA.findIndex(([f]) => f === b) : 99));
  for (const [field, value] of entries) {
    const { name, kind } = known.get(field) || { name: field, kind: "raw" };
    const tile = document.createElement("div");
    const dt = document.createElement("dt");
    dt.textContent = name;
    const dd = document.createElement("dd");
    dd.id = `club-${field}`;
    dd.title = `${name}: ${value}`;  // a long value is cut with an ellipsis on the tile; the whole of it on hover
    tile.append(dt, dd);
    list.appendChild(tile);
    if (typeof value !== "number") {
      dd.textContent = String(value);
    } else if (kind === "speed") {
      setNumber(dd.id, speedText(value * MPH_MPS), speedUnit());
    } else if (kind === "deg") {
      setNumber(dd.id, fixed(value), "°");
    } else if (kind === "deg/s") {
      setNumber(dd.id, fixed(value), "°/s");
    } else {
      dd.textContent = String(Number(value.toFixed(2)));
    }
  }
  list.hidden = title.hidden = entries.length === 0;
}

/** How the last shot was read, when that is not what one would guess (the reply's flown_in.note: a full swing with
 * the putter selected, flown as a full shot); hidden otherwise. */
function showNote(shot) {
  const note = document.getElementById("shot-note");
  const flownIn = shot ? shot.event.flight.flown_in : null;
  note.textContent = flownIn && flownIn.note ? flownIn.note : "";
  note.hidden = !note.textContent;
}

function showNumbers(shot) {
  const source = document.getElementById("last-source");
  source.textContent = shot
    ? `#${shotNumber(shot)} · ${SOURCES[shot.event.source]}${shot.event.shot_number ? " shot " + shot.event.shot_number : ""}`
      + (shot.club ? ` · ${clubName(shot.club)}` : "") + (shot.event.putt ? " putt" : "")
    : "";
  showClubData(shot ? shot.event.club_data : null);
  showNote(shot);
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
  const flew = !shot.event.putt;  // a putt rolls from the start: no carry, apex, landing or hang time
  setNumber("n-carry", flew ? fixed(distance(flight, "carry")) : "—", unit);
  setNumber("n-total", fixed(distance(flight, "total")), unit);
  setNumber("n-roll", fixed(distance(flight, "roll")), unit);
  setNumber("n-apex", flew ? fixed(distance(flight, "apex")) : "—", unit);
  setNumber("n-landing-angle", flew ? fixed(flight.landing_angle_deg) : "—", "°");
  const [lateral, lateralHand] = flew ? side(distance(flight, "lateral")) : ["—", ""];
  setNumber("n-lateral", lateral, unit, lateralHand);
  setNumber("n-flight-time", flew ? fixed(flight.flight_time_s) : "—", "s");
}

/** The club cell: the GSPro code (its name on hover), "putt" after a putter's, "—" for a shot without a player. */
function clubCell(shot) {
  const cell = document.createElement("td");
  cell.textContent = shot.club || "—";
  if (shot.club) cell.title = clubName(shot.club);
  if (shot.event.putt) {
    const mark = document.createElement("span");
    mark.className = "putt";
    mark.textContent = "putt";
    cell.append(" ", mark);
  }
  return cell;
}

function showTable() {
  const body = document.querySelector("#shots tbody");
  body.replaceChildren();
  for (const shot of [...state.shots].reverse()) {
    const { launch, flight } = shot.event;
    const row = document.createElement("tr");
    row.dataset.shot = shot.event.id;
    row.dataset.club = shot.club;
    if (shot.event.putt) row.dataset.putt = "1";
    const flew = !shot.event.putt;  // a putt: its roll in `total`, no carry, apex, landing or lateral at landing
    const cells = [
      String(shotNumber(shot)), SOURCES[shot.event.source], null,
      speedText(launch.ball_speed_mps), `${fixed(launch.launch_angle_deg)}°`, rpm(launch.spin_rpm),
      flew ? fixed(distance(flight, "carry")) : "—", fixed(distance(flight, "total")),
      flew ? fixed(distance(flight, "apex")) : "—", flew ? `${fixed(flight.landing_angle_deg)}°` : "—",
      flew ? side(distance(flight, "lateral")).join(" ").trim() : "—",
    ];
    for (const text of cells) {
      if (text === null) {
        row.appendChild(clubCell(shot));
        continue;
      }
      const cell = document.createElement("td");
      cell.textContent = text;
      row.appendChild(cell);
    }
    body.appendChild(row);
  }
  const head = document.querySelectorAll("#shots th");
  // the units in the headers, not in every cell: the columns stay narrow enough for a phone's 400 px
  for (const [index, name, unit] of [[3, "ball speed", speedUnit()], [6, "carry"], [7, "total"], [8, "apex"], [10, "lateral"]]) {
    head[index].textContent = `${name} (${unit || distUnit()})`;
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
  showPin();
  showToPin(latest());
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

/** The pictures are drawn at their size on screen: drawn again when a view's width changes. */
function redrawOnResize() {
  let pending = false;
  const widths = new Map();
  const observer = new ResizeObserver((entries) => {
    const changed = entries.some((entry) => {
      const width = Math.round(entry.contentRect.width);
      const before = widths.get(entry.target);
      widths.set(entry.target, width);
      return before !== undefined && before !== width;
    });
    if (!changed || pending) return;
    pending = true;
    requestAnimationFrame(() => {
      pending = false;
      const box = drawViews();
      drawDispersion(document.getElementById("dispersion"), box);
    });
  });
  for (const id of ["behind", "side", "top", "dispersion"]) observer.observe(document.getElementById(id));
}

// ---- the bay (GET and PATCH /v1/bay): its conditions shown and changed from the form, its units used for every
// figure, its player's club in the club menu. A change sends the part it changes only, so nothing another screen
// or client set is written back, and nothing is rounded through the display units. ---------------------------

/** The form's fields: where each lives in the bay, the field's name in each of the page's units (the API takes
 * both: temperature_f or temperature_c, altitude_ft or altitude_m, speed_mph or speed_mps, elevation_ft or
 * elevation_m), and how a value in the other converts. */
const BAY_FIELDS = [
  { id: "bay-temperature", group: "air", imperial: "temperature_f", metric: "temperature_c", digits: 1,
    units: ["°F", "°C"], toImperial: (c) => c * 9 / 5 + 32, toMetric: (f) => (f - 32) * 5 / 9 },
  { id: "bay-altitude", group: "air", imperial: "altitude_ft", metric: "altitude_m", digits: 0,
    units: ["ft", "m"], toImperial: (m) => m / FEET_M, toMetric: (ft) => ft * FEET_M },
  { id: "bay-humidity", group: "air", imperial: "humidity_pct", metric: "humidity_pct", digits: 0, units: ["%", "%"] },
  { id: "bay-wind-speed", group: "wind", imperial: "speed_mph", metric: "speed_mps", digits: 1,
    units: ["mph", "m/s"], toImperial: (mps) => mps / MPH_MPS, toMetric: (mph) => mph * MPH_MPS },
  { id: "bay-wind-from", group: "wind", imperial: "from_deg", metric: "from_deg", digits: 0, units: ["°", "°"] },
  { id: "bay-stimp", group: "ground", imperial: "stimp_ft", metric: "stimp_ft", digits: 1, units: ["ft", "ft"] },
  { id: "bay-elevation", group: "ground", imperial: "elevation_ft", metric: "elevation_m", digits: 1,
    units: ["ft", "m"], toImperial: (m) => m / FEET_M, toMetric: (ft) => ft * FEET_M },
];

/** A field's value in the bay in `units` ("imperial" or "metric"): as the bay has it in those units, else
 * converted from the other's; undefined when the bay has neither. */
function bayValue(bay, field, units = state.units) {
  const part = bay && bay[field.group];
  if (!part) return undefined;
  const wanted = units === "imperial" ? field.imperial : field.metric;
  const other = units === "imperial" ? field.metric : field.imperial;
  if (typeof part[wanted] === "number") return part[wanted];
  if (typeof part[other] === "number") return (units === "imperial" ? field.toImperial : field.toMetric)(part[other]);
  return undefined;
}

function fieldUnit(field) { return field.units[imperial() ? 0 : 1]; }

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

/** The bay's conditions in a line, in the page's units. */
function baySummary(bay) {
  const [temperature, altitude, humidity, windSpeed, windFrom, stimp, elevation] = BAY_FIELDS;
  const parts = [];
  const air = bay.air || {};
  if (air.density_kg_m3 !== undefined) parts.push(`air ${air.density_kg_m3} kg/m³`);
  else {
    const t = bayValue(bay, temperature);
    parts.push(t === undefined ? "15 °C standard air" : `${fixed(t, 1)}${fieldUnit(temperature)}`);
    const a = bayValue(bay, altitude);
    if (a !== undefined) parts.push(`${fixed(a, 0)} ${fieldUnit(altitude)} up`);
    if (air.pressure_hpa !== undefined) parts.push(`${air.pressure_hpa} hPa`);
    if (bayValue(bay, humidity) !== undefined) parts.push(`${bayValue(bay, humidity)}% humidity`);
  }
  const speed = bayValue(bay, windSpeed);
  parts.push(speed ? `wind ${fixed(speed)} ${fieldUnit(windSpeed)} from ${Math.round(bayValue(bay, windFrom) || 0)}°` : "calm");
  const ground = bay.ground || {};
  const s = bayValue(bay, stimp), e = bayValue(bay, elevation);
  parts.push((ground.surface || "fairway").replace("_", " ") + (s !== undefined ? `, stimp ${s}` : "")
    + (e ? `, ${e > 0 ? "+" : "−"}${fixed(Math.abs(e), 1)} ${fieldUnit(elevation)} from the tee` : ""));
  return parts.join(" · ");
}

/** The form and the summary from `state.bay`; the fields the operator is editing are left alone unless `all`. */
function showBay(all = true) {
  const bay = state.bay;
  if (!bay) return;
  document.getElementById("bay-summary").textContent = baySummary(bay);
  for (const field of BAY_FIELDS) {
    const input = document.getElementById(field.id);
    document.querySelector(`label[for=${field.id}] .unit`).textContent = fieldUnit(field);
    if (!all && changedField(input)) continue;
    const value = bayValue(bay, field);
    input.value = typeof value === "number" ? String(Number(value.toFixed(field.digits))) : "";
    input.dataset.shown = input.value;  // a field is changed when it no longer reads this
  }
  const surface = document.getElementById("bay-surface");
  if (all || !changedField(surface)) {
    surface.value = (bay.ground && bay.ground.surface) || "fairway";
    surface.dataset.shown = surface.value;
  }
  document.getElementById("bay-stimp").disabled = surface.value !== "green";
}

function changedField(input) { return input.dataset.shown !== undefined && input.value.trim() !== input.dataset.shown; }

/** Takes the bay the service answered with: its units become the page's, its player's club the menu's. */
function takeBay(bay, all = true) {
  state.bay = bay;
  const club = document.getElementById("club");
  if (bay.player && bay.player.club && club.value !== bay.player.club) club.value = bay.player.club;
  if (bay.player) club.dataset.saved = bay.player.club;
  if (bay.units && bay.units !== state.units) {
    state.units = bay.units;
    localStorage.setItem("golfflight-units", state.units);
  }
  render();  // the ground's elevation and the units draw the pictures
  showBay(all);
}

async function loadBay() {
  try {
    const response = await fetch("v1/bay", { headers: keyHeaders(), cache: "no-store" });
    if (response.ok) {
      const editing = document.getElementById("bay-form").contains(document.activeElement);
      takeBay(await response.json(), !editing);
    }
  } catch (error) { /* the stream's status says so */ }
}

/** PATCH /v1/bay with `update` (the parts to change, nothing else); the bay the service answers is taken, and a
 * refusal shown in the service's own words: true when it was saved. */
async function patchBay(update) {
  bayMessage("saving", "saving…");
  try {
    const response = await fetch("v1/bay", {
      method: "PATCH", headers: { ...keyHeaders(), "Content-Type": "application/json" }, body: JSON.stringify(update),
    });
    const answer = await response.json().catch(() => null);
    if (!response.ok) {
      bayMessage("refused", refusal(response.status, answer));
      return false;
    }
    if (answer && typeof answer === "object" && answer.units) takeBay(answer);
    else await loadBay();
    bayMessage("saved", "saved");
    return true;
  } catch (error) {
    bayMessage("refused", "service unreachable");
    return false;
  }
}

/** The parts of the bay the form changes (PATCH replaces each part it names): a part with a changed field goes as
 * the bay had it, the changed field set as typed under its name in the page's units (°F, ft, mph when imperial) and
 * its other spelling dropped; an emptied field is removed, a part left empty (a wind without speed) is cleared
 * with null. Parts nobody changed are not sent at all, and untouched values go back exactly as they came. */
function bayUpdate() {
  const bay = state.bay || {};
  const parts = {}, changed = new Set();
  for (const group of ["air", "wind", "ground"]) parts[group] = structuredClone(bay[group] || {});
  for (const field of BAY_FIELDS) {
    const input = document.getElementById(field.id);
    if (!changedField(input) || input.disabled) continue;
    const part = parts[field.group];
    delete part[field.imperial];
    delete part[field.metric];
    const text = input.value.trim();
    if (text !== "") {
      const number = Number(text);
      part[imperial() ? field.imperial : field.metric] = Number.isFinite(number) ? number : text;
    }
    changed.add(field.group);
  }
  const surface = document.getElementById("bay-surface");
  if (changedField(surface)) {
    parts.ground.surface = surface.value;
    if (surface.value !== "green") delete parts.ground.stimp_ft;
    changed.add("ground");
  }
  const update = {};
  for (const group of changed) {
    const part = parts[group];
    const calm = group === "wind" && part.speed_mps === undefined && part.speed_mph === undefined;
    update[group] = calm || Object.keys(part).length === 0 ? null : part;
  }
  return update;
}

/** The units button: PATCH {"units": ...} and nothing else; before the bay is read, this screen only. */
async function setUnits(units) {
  if (state.bay) {
    await patchBay({ units });
    return;
  }
  state.units = units;
  localStorage.setItem("golfflight-units", state.units);
  render();
  showBay(true);
}

/** The club menu: the bay's player's club, PATCH {"player": {"club": CODE}}; the shots hit from now on carry it.
 * A refused change puts the menu back to the bay's club. */
async function setClub(code) {
  const club = document.getElementById("club");
  delete club.dataset.saved;
  if (!(await patchBay({ player: { club: code } })) && state.bay && state.bay.player) {
    club.value = state.bay.player.club;
    club.dataset.saved = state.bay.player.club;
  }
}

// ---- the session's shots as CSV (GET /v1/session.csv): fetched with the key, saved from a blob URL ------------

async function downloadSession() {
  const message = document.getElementById("download-message");
  message.dataset.state = "loading";
  message.textContent = "";
  try {
    const response = await fetch("v1/session.csv", { headers: keyHeaders("text/csv"), cache: "no-store" });
    if (!response.ok) {
      const answer = await response.json().catch(() => null);
      message.dataset.state = "refused";
      message.textContent = refusal(response.status, answer);
      return;
    }
    const url = URL.createObjectURL(await response.blob());
    const link = document.createElement("a");
    link.href = url;
    link.download = `golfflight-session-${session.shown ? session.shown.id : "current"}.csv`;
    document.body.appendChild(link);
    link.click();
    link.remove();
    setTimeout(() => URL.revokeObjectURL(url), 60_000);
    message.dataset.state = "done";
  } catch (error) {
    message.dataset.state = "refused";
    message.textContent = "service unreachable";
  }
}

// ---- start --------------------------------------------------------------------------------------------------

document.addEventListener("DOMContentLoaded", () => {
  const club = document.getElementById("club");
  for (const option of club.options) CLUB_NAMES.set(option.value, option.textContent);
  club.addEventListener("change", () => setClub(club.value));
  for (const button of document.querySelectorAll(".units button")) {
    button.addEventListener("click", () => setUnits(button.dataset.units));
  }
  document.getElementById("download-csv").addEventListener("click", downloadSession);
  const pin = document.getElementById("pin");
  pin.addEventListener("change", () => setPin(pin.value));
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
  bayForm.addEventListener("input", () => {
    document.getElementById("bay-stimp").disabled = document.getElementById("bay-surface").value !== "green";
  });
  bayForm.addEventListener("submit", async (event) => {
    event.preventDefault();
    const update = bayUpdate();
    if (Object.keys(update).length === 0) {
      bayMessage("unchanged", "nothing changed");
      return;
    }
    await patchBay(update);
  });
  bayForm.addEventListener("reset", (event) => {
    event.preventDefault();
    showBay(true);
    bayMessage("", "");
  });
  render();
  redrawOnResize();
  follow();
  loadBay();
  setInterval(loadBay, BAY_POLL_MS);
});
