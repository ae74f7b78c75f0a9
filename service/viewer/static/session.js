// golfflight live shot viewer: the bay's session. Loaded after viewer.js, whose state and drawing helpers it uses.
// The stream's `session` event (first on every stream, and whenever a session starts) names the session the screens
// show: a different one than the page shows empties the screen. "New session" starts one (POST /v1/sessions, a
// player's name optional). The session's summary per club (GET /v1/session/summary: shots, mean and spread, carry
// gaps, 95 % ellipses) is read after each shot and shown in a table and as ellipses on the dispersion view.
"use strict";

const SUMMARY_DELAY_MS = 300;     // a burst of kept shots on a reload reads the summary once
const ELLIPSE_POINTS = 72;        // an ellipse is drawn as a polygon through the projection of the dispersion view

const session = {
  shown: null,                     // the SessionInfo the screen shows (the stream's last `session` event)
  summary: null,                   // its SessionSummary as last read
  reading: null,                   // the pending summary read's timer
};

function metres(value) { return value === null || value === undefined ? null : imperial() ? value / YARD_M : value; }

/** Two sessions are the same when their ids and start times are: ids restart with the service. */
function sameSession(a, b) { return a && b && a.id === b.id && a.started_unix_s === b.started_unix_s; }

/** The session the service names (its `session` event, or the answer to POST /v1/sessions): another than the one
 * shown empties the screen: shots, paths, numbers, dispersion and summary. */
function onSession(info) {
  const changed = !sameSession(session.shown, info);
  session.shown = info;
  showSessionTitle();
  if (!changed) return;
  state.shots = [];
  state.play = null;
  session.summary = null;
  for (const tile of document.querySelectorAll(".numbers dl:not(#club-numbers) dd")) tile.textContent = "—";
  render();
  readSummarySoon();
}

function showSessionTitle() {
  const info = session.shown;
  const title = document.getElementById("session-title");
  if (!info) {
    title.textContent = "";
    return;
  }
  const since = new Date(info.started_unix_s * 1000).toLocaleTimeString([], { hour: "2-digit", minute: "2-digit" });
  title.textContent = `Session ${info.id}${info.player ? " · " + info.player : ""} · since ${since}`;
  title.dataset.session = info.id;
}

/** GET /v1/session/summary once, shortly. */
function readSummarySoon() {
  if (session.reading === null) session.reading = setTimeout(() => { session.reading = null; readSummary(); }, SUMMARY_DELAY_MS);
}

async function readSummary() {
  try {
    const response = await fetch("v1/session/summary", { headers: keyHeaders(), cache: "no-store" });
    if (!response.ok) return;
    const summary = await response.json();
    if (session.shown && !sameSession(session.shown, summary.session)) return;  // another session since
    session.summary = summary;
    drawDispersion(document.getElementById("dispersion"), extent());
  } catch (error) { /* the stream's status says so */ }
}

/** A club's name in the summary: its code's name, "putts" after a putter's, "no club" for a batch's shots. */
function summaryClubName(row) {
  return (row.club ? clubName(row.club) : "no club") + (row.putts ? " (putts)" : "");
}

/** The ellipse's points in metres: centre, semi-axes and the long axis' angle from the target line (+ = right). */
function ellipsePoints(e) {
  const a = (e.angle_deg * Math.PI) / 180;
  const major = [Math.sin(a), Math.cos(a)], minor = [Math.cos(a), -Math.sin(a)];  // (x, y): right, down the line
  const points = [];
  for (let k = 0; k < ELLIPSE_POINTS; k++) {
    const t = (2 * Math.PI * k) / ELLIPSE_POINTS;
    const u = e.semi_major_m * Math.cos(t), v = e.semi_minor_m * Math.sin(t);
    points.push([e.center_x_m + u * major[0] + v * minor[0], e.center_y_m + u * major[1] + v * minor[1]]);
  }
  return points;
}

/** The summary on the dispersion view (called by drawDispersion with its projection and club colours): each
 * club's 95 % ellipse, of its landing points (a putter's: of its rest points), clipped to the picture; then the
 * table in the same colours. */
function drawSummary(svg, project, colour) {
  const rows = session.summary ? session.summary.clubs : [];
  const box = svg.viewBox.baseVal;
  el(el(svg, "clipPath", { id: "ellipse-clip" }), "rect", { x: 0, y: 0, width: box.width, height: box.height });
  const group = el(svg, "g", { class: "ellipses", "clip-path": "url(#ellipse-clip)" });
  for (const row of rows) {
    const shape = row.putts ? row.rest : row.landing;
    if (!shape) continue;
    const points = ellipsePoints(shape).map(([x, y]) => project(x, y).map((v) => v.toFixed(1)).join(",")).join(" ");
    const line = el(group, "polygon", { class: "ellipse", points, "data-club": row.club || "", "data-putts": row.putts ? "1" : "0" });
    line.style.stroke = colour(row.club || "") || "var(--muted)";
  }
  showSummary(rows, colour);
}

/** A mean and its spread as "152.3 ± 4.1" in the page's units ("152.3" with one shot). */
function spreadText(spread, signed = false) {
  const mean = metres(spread.mean_m);
  const text = signed ? side(mean).join(" ").trim() : fixed(mean);
  return spread.sd_m === undefined || spread.sd_m === null ? text : `${text} ± ${fixed(metres(spread.sd_m))}`;
}

/** The summary table: a row per club in the bag's order. */
function showSummary(rows, colour) {
  const body = document.querySelector("#summary tbody");
  body.replaceChildren();
  for (const row of rows) {
    const line = document.createElement("tr");
    line.dataset.club = row.club || "";
    if (row.putts) line.dataset.putts = "1";
    const shape = row.putts ? row.rest : row.landing;
    const flew = !row.putts;  // putts roll from the start: their total is the roll; no carry, apex or landing
    const cells = [
      summaryClubName(row), String(row.shots), flew ? spreadText(row.carry) : "—",
      row.carry_gap_m === undefined || row.carry_gap_m === null ? "—" : fixed(metres(row.carry_gap_m)),
      spreadText(row.total), flew ? spreadText(row.apex) : "—", flew ? spreadText(row.lateral, true) : "—",
      shape ? `${fixed(metres(2 * shape.semi_major_m))} × ${fixed(metres(2 * shape.semi_minor_m))}` : "—",
    ];
    for (const text of cells) {
      const cell = document.createElement("td");
      cell.textContent = text;
      line.appendChild(cell);
    }
    line.cells[0].style.setProperty("--swatch", colour(row.club || "") || "var(--muted)");
    body.appendChild(line);
  }
  const unit = distUnit();
  const head = document.querySelectorAll("#summary th");
  for (const [index, name] of [[2, "carry"], [3, "gap"], [4, "total"], [5, "apex"], [6, "lateral"], [7, "95 % ellipse"]]) {
    head[index].textContent = `${name} (${unit})`;
  }
  // each cell carries its column's name: on a phone the rows stack, one club a card, each number under its name
  for (const line of body.rows) {
    [...line.cells].forEach((cell, index) => { cell.dataset.label = head[index].textContent; });
  }
  document.getElementById("summary").hidden = rows.length === 0;
}

/** "New session": POST /v1/sessions with the player's name when one is typed; the screen empties at once (the
 * stream's `session` event then names the same session). A refusal shows the service's words. */
async function startSession(event) {
  event.preventDefault();
  const message = document.getElementById("session-message");
  const name = document.getElementById("session-player").value.trim();
  message.dataset.state = "saving";
  message.textContent = "";
  try {
    const response = await fetch("v1/sessions", {
      method: "POST", headers: { ...keyHeaders(), "Content-Type": "application/json" },
      body: JSON.stringify(name ? { player: name } : {}),
    });
    const answer = await response.json().catch(() => null);
    if (!response.ok) {
      message.dataset.state = "refused";
      message.textContent = refusal(response.status, answer);
      return;
    }
    onSession(answer);
    document.getElementById("session-player").value = "";
    message.dataset.state = "started";
  } catch (error) {
    message.dataset.state = "refused";
    message.textContent = "service unreachable";
  }
}

document.addEventListener("DOMContentLoaded", () => {
  document.getElementById("session-form").addEventListener("submit", startSession);
});
