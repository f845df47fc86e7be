// The page wirc-recorder's web server shows at "/": every camera live as
// MJPEG (the camera's own frames, not re-encoded), the AprilTags found in
// them drawn over the picture from the /api/events stream, the status, a
// map of the vehicles' Marvelmind positions with their trails (when
// --marvelmind is on) and the recordings. Self-contained: no scripts from
// elsewhere. The server puts the cameras, their last detections and the
// position trails in place of INITIAL_STATE, so the first picture already
// carries its overlay and the map its trails, and the player
// (page_player_script.h) and control (page_control_script.h) scripts in
// place of PLAYER_SCRIPT and CONTROL_SCRIPT.
#pragma once

namespace wircam::recorder {

inline constexpr const char kLiveViewPage[] = R"html(<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>wirc-recorder</title>
<meta name="viewport" content="width=device-width, initial-scale=1">
<style>
body { background: #15171a; color: #e8e8e8; font: 14px sans-serif; margin: 16px; }
h1 { font-size: 20px; margin: 0 0 12px; } h2 { font-size: 16px; }
.camera { display: inline-block; margin: 0 16px 16px 0; vertical-align: top; background: #202328;
          border-radius: 8px; padding: 10px; width: min(640px, calc(100vw - 52px)); }
.head { display: flex; align-items: center; gap: 8px; margin-bottom: 8px; flex-wrap: wrap; }
.badge { border-radius: 4px; padding: 2px 8px; font-size: 12px; font-weight: bold; color: #fff; }
.badge.live { background: #1b873f; } .badge.offline { background: #c53030; }
.badge.waiting, .badge.connecting { background: #8a6d1d; }
.since { color: #aab; font-size: 12px; }
.view { position: relative; line-height: 0; background: #000; }
.view img { display: block; width: 100%; height: auto; }
.view svg { position: absolute; left: 0; top: 0; width: 100%; height: 100%; }
.placeholder { display: none; aspect-ratio: 4 / 3; align-items: center; justify-content: center;
               line-height: 1.4; color: #889; background: repeating-linear-gradient(45deg, #111,
               #111 12px, #171717 12px, #171717 24px); font-size: 16px; text-align: center; }
.camera:not([data-state="live"]) .view img, .camera:not([data-state="live"]) .view svg
  { display: none; }
.camera:not([data-state="live"]) .placeholder { display: flex; }
.tag { fill: none; stroke: #00ff00; stroke-width: 3; }
.label { fill: #00ff00; font: bold 18px sans-serif; }
.stats { margin-top: 6px; color: #aab; font-family: monospace; }
a { color: #8cf; } td { padding: 2px 12px 2px 0; }
h3 { font-size: 14px; margin: 12px 0 4px; color: #ccd; }
td.number { text-align: right; font-family: monospace; }
button.delete { background: none; color: #e88; border: 1px solid #744; border-radius: 4px;
                font: inherit; font-size: 12px; padding: 1px 8px; cursor: pointer; }
#map { width: 100%; max-width: 480px; background: #0d0f12; border: 1px solid #333; }
#map .grid { stroke: #263040; stroke-width: 1; vector-effect: non-scaling-stroke; }
#map .trail { fill: none; stroke-width: 2; vector-effect: non-scaling-stroke; }
#map .stale { stroke-dasharray: 4 3; opacity: 0.5; }
#map text { font: 11px sans-serif; fill: #ccd; }
[hidden] { display: none !important; }
button { background: #2b3038; color: #e8e8e8; border: 1px solid #445; border-radius: 4px;
         font: inherit; font-size: 13px; padding: 3px 10px; cursor: pointer; }
button.on { background: #1b6f3f; border-color: #2a9d5c; }
.controls { margin-top: 8px; display: flex; flex-wrap: wrap; gap: 6px; align-items: center; }
.controls input { width: 4em; background: #15171a; color: #e8e8e8; border: 1px solid #445; }
.drive-info { color: #8cf; font-family: monospace; }
.control-message { flex-basis: 100%; color: #e88; }
.camera[data-driving="true"] { outline: 2px solid #4fc3f7; }
#player { max-width: 680px; background: #202328; border-radius: 8px; padding: 10px; }
#player h2 { display: flex; gap: 8px; align-items: center; margin-top: 0; font-size: 15px; }
#player-title { font-weight: normal; color: #aab; overflow-wrap: anywhere; flex: 1; }
#player img, #player video { display: block; width: 100%; background: #000; }
/* A phone: each recording's cells wrap instead of running off the side. */
@media (max-width: 560px) {
  #recordings tr { display: flex; flex-wrap: wrap; align-items: center; margin-bottom: 6px; }
  body { margin: 8px; } .camera { width: calc(100vw - 36px); margin-right: 0; }
}
#timeline { display: block; width: 100%; height: 104px; margin-top: 8px; cursor: pointer; }
</style></head>
<body>
<h1>wirc-recorder</h1>
<div id="cameras"></div>
<section id="positions" hidden><h2>Positions</h2><svg id="map" viewBox="0 0 480 360"></svg></section>
<section id="player" hidden><h2>Playback <span id="player-title"></span>
<button id="player-close">close</button></h2><img id="playback-image" alt="playback">
<video id="playback-video" controls hidden></video>
<div class="stats" id="playback-time"></div><canvas id="timeline"></canvas></section>
<h2>Recordings</h2>
<div id="recordings"></div>
<p id="recording-message" class="since"></p>
<script>
"use strict";
const svgNs = "http://www.w3.org/2000/svg";
const views = {};

function addCamera(camera) {
  const box = document.createElement("div");
  box.className = "camera";
  box.innerHTML = `<div class="head"><b></b><span class="badge"></span><span class="since">` +
                  `</span></div><div class="view"><img alt="live"><svg></svg>` +
                  `<div class="placeholder"></div></div><div class="stats"></div>`;
  box.querySelector("b").textContent = camera.name;
  document.getElementById("cameras").appendChild(box);
  views[camera.name] = { box, img: box.querySelector("img"), svg: box.querySelector("svg"),
                         badge: box.querySelector(".badge"), since: box.querySelector(".since"),
                         placeholder: box.querySelector(".placeholder"),
                         stats: box.querySelector(".stats"),
                         width: camera.width, height: camera.height, state: "" };
  if (camera.status && camera.status.following !== undefined)
    addControls(views[camera.name], camera.name);
  if (camera.status) showStream(camera.status);
  else setState(views[camera.name], "live", null);
  showDetections({ stream: camera.name, detections: camera.detections });
}

// live, offline, or waiting for device (with since when). Not live: a
// placeholder saying so, never a broken image or a stale tag box; live
// again: the picture reconnects.
function setState(view, state, sinceUtc) {
  const kind = state === "live" ? "live" : state === "offline" ? "offline" : "waiting";
  const since = sinceUtc ? new Date(sinceUtc) : null;
  const sinceText = since ? "since " + since.toLocaleTimeString() : "";
  view.badge.className = "badge " + kind;
  view.badge.textContent = state;
  view.since.textContent = sinceText;
  view.placeholder.textContent = state === "offline" ? `offline ${sinceText}: the device is ` +
      "off, out of range or gone; it is reconnected to when it is back" : "waiting for device";
  if (view.state !== kind) {
    view.box.dataset.state = kind;
    if (kind === "live") {
      const name = view.box.querySelector("b").textContent;
      view.img.src = "/live/" + encodeURIComponent(name) + ".mjpg?t=" + Date.now();
    } else {
      view.img.removeAttribute("src");
      view.svg.replaceChildren();
    }
    view.state = kind;
  }
}

function showDetections(event) {
  const view = views[event.stream];
  if (!view || view.state !== "live") return;
  const width = view.img.naturalWidth || view.width, height = view.img.naturalHeight || view.height;
  if (!width || !height) return;
  view.svg.setAttribute("viewBox", `0 0 ${width} ${height}`);
  view.svg.replaceChildren();
  for (const tag of event.detections) {
    const outline = document.createElementNS(svgNs, "polygon");
    const points = [];
    for (let i = 0; i < 8; i += 2) points.push(tag.corners[i] + "," + tag.corners[i + 1]);
    outline.setAttribute("points", points.join(" "));
    outline.setAttribute("class", "tag");
    const label = document.createElementNS(svgNs, "text");
    label.setAttribute("x", tag.cx);
    label.setAttribute("y", tag.cy);
    label.setAttribute("class", "label");
    label.textContent = tag.id;
    view.svg.append(outline, label);
  }
}

// Each vehicle's trail of Marvelmind positions, newest last.
const trails = {};
const kTrailPoints = 600;
const colours = ["#4fc3f7", "#ffb74d", "#aed581", "#f06292", "#ba68c8", "#fff176"];

function positionText(position) {
  if (position === undefined) return "";
  if (position === null) return "  position: none yet";
  if (position.x === undefined) return "  position: stale";
  return `  at ${position.x.toFixed(2)}, ${position.y.toFixed(2)} m` +
         (position.stale ? " (stale)" : "");
}

function controlText(stream) {
  if (stream.following === undefined) return "";
  const target = stream.target >= 0 ? `tag ${stream.target}` : "largest tag";
  return `  control ${stream.has_control ? "yes" : "no"}  following ` +
         (stream.following ? `on (${target})` : "off");
}

function showStream(stream) {
  const view = views[stream.name];
  if (!view) return;
  setState(view, stream.state, stream.state_since_utc);
  showControls(view, stream);
  view.stats.textContent = `${stream.fps.toFixed(1)} fps  ` +
      `loss ${stream.loss_percent.toFixed(1)} %  ${Math.round(stream.kbps)} kbit/s  ` +
      `battery ${stream.battery_v.toFixed(2)} V` +
      (stream.status_stale ? ` (stale, ${Math.round(stream.status_age_ms / 1000)} s old)` : "") +
      controlText(stream) + positionText(stream.position);
}

function showStatus(status) {
  for (const stream of status.streams) {
    showStream(stream);
    const p = stream.position;
    if (!p || p.x === undefined) continue;
    const trail = trails[stream.name] || (trails[stream.name] = { points: [] });
    const last = trail.points[trail.points.length - 1];
    if (!last || last.utc !== p.utc) trail.points.push({ x: p.x, y: p.y, utc: p.utc });
    if (trail.points.length > kTrailPoints) trail.points.shift();
    trail.stale = p.stale;
  }
  drawMap();
}

// Metres to the map's 480×360 units: every trail in view, 1 m grid, y up.
function drawMap() {
  const names = Object.keys(trails);
  if (!names.length) return;
  document.getElementById("positions").hidden = false;
  const all = names.flatMap(name => trails[name].points);
  let minX = Math.min(...all.map(p => p.x)), maxX = Math.max(...all.map(p => p.x));
  let minY = Math.min(...all.map(p => p.y)), maxY = Math.max(...all.map(p => p.y));
  const span = Math.max(maxX - minX, (maxY - minY) * 4 / 3, 2) + 1;
  const scale = 480 / span;
  const centreX = (minX + maxX) / 2, centreY = (minY + maxY) / 2;
  const toMap = p => [240 + (p.x - centreX) * scale, 180 - (p.y - centreY) * scale];
  const map = document.getElementById("map");
  map.replaceChildren();
  const element = (tag, attributes) => {
    const e = document.createElementNS(svgNs, tag);
    for (const [key, value] of Object.entries(attributes)) e.setAttribute(key, value);
    map.appendChild(e);
    return e;
  };
  if (span < 60) {
    for (let x = Math.ceil(centreX - span / 2); x <= centreX + span / 2; ++x) {
      const [mx] = toMap({ x, y: 0 });
      element("line", { x1: mx, y1: 0, x2: mx, y2: 360, class: "grid" });
    }
    for (let y = Math.ceil(centreY - span * 3 / 8); y <= centreY + span * 3 / 8; ++y) {
      const [, my] = toMap({ x: 0, y });
      element("line", { x1: 0, y1: my, x2: 480, y2: my, class: "grid" });
    }
    element("text", { x: 6, y: 352 }).textContent = "grid: 1 m";
  }
  names.forEach((name, i) => {
    const trail = trails[name], colour = colours[i % colours.length];
    const points = trail.points.map(p => toMap(p).join(",")).join(" ");
    element("polyline", { points, stroke: colour, class: "trail" + (trail.stale ? " stale" : "") });
    const [x, y] = toMap(trail.points[trail.points.length - 1]);
    element("circle", { cx: x, cy: y, r: 6, fill: trail.stale ? "#777" : colour });
    element("text", { x: x + 9, y: y + 4 }).textContent = name + (trail.stale ? " (stale)" : "");
  });
}

async function refreshStatus() {
  showStatus(await (await fetch("/api/status")).json());
}

// The finished segments from the recording index, by camera and by day
// (local time), newest first: start, duration, size, frames, download,
// delete (which the server allows only with the access token).
async function refresh() {
  const segments = await (await fetch("/api/recordings")).json();
  const groups = new Map();
  for (const segment of segments.reverse()) {
    const start = new Date(segment.start_utc);
    const key = `${segment.camera} · ${start.toLocaleDateString()}`;
    if (!groups.has(key)) groups.set(key, []);
    groups.get(key).push({ ...segment, start });
  }
  const box = document.getElementById("recordings");
  box.replaceChildren();
  for (const [title, list] of groups) {
    const heading = document.createElement("h3");
    heading.textContent = title;
    const table = document.createElement("table");
    for (const segment of list) {
      const row = table.insertRow();
      row.insertCell().textContent = segment.start.toLocaleTimeString();
      const cells = [`${segment.duration_s.toFixed(1)} s`,
                     `${(segment.bytes / 1e6).toFixed(1)} MB`, `${segment.frames} frames`];
      for (const text of cells) {
        const cell = row.insertCell();
        cell.className = "number";
        cell.textContent = text;
      }
      const play = document.createElement("button");
      play.className = "play";
      play.textContent = "play";
      play.addEventListener("click", () => openPlayer(segment));
      row.insertCell().appendChild(play);
      const link = document.createElement("a");
      link.href = segment.url;
      link.textContent = "download";
      row.insertCell().appendChild(link);
      const remove = document.createElement("button");
      remove.className = "delete";
      remove.textContent = "delete";
      remove.addEventListener("click", () => deleteSegment(segment.file));
      row.insertCell().appendChild(remove);
    }
    box.append(heading, table);
  }
}

async function deleteSegment(file) {
  if (!confirm(`Delete ${file} and its telemetry?`)) return;
  const response = await fetch("/api/recordings/" + encodeURIComponent(file),
                               { method: "DELETE" });
  const answer = await response.json();
  document.getElementById("recording-message").textContent =
      response.ok ? `deleted ${file}` : answer.error;
  refresh();
}

PLAYER_SCRIPT
CONTROL_SCRIPT

function start() {
  // Built before the page's load event, so a screenshot at load shows them.
  const initial = INITIAL_STATE;
  initial.cameras.forEach(addCamera);
  Object.assign(trails, initial.trails);
  drawMap();
  const events = new EventSource("/api/events");
  events.addEventListener("detections", e => showDetections(JSON.parse(e.data)));
  refreshStatus();
  refresh();
  // Twice a second: the trails follow the vehicles.
  setInterval(refreshStatus, 500);
  setInterval(refresh, 2000);
}
start();
</script>
</body></html>
)html";

}  // namespace wircam::recorder
