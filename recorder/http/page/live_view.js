"use strict";
const svgNs = "http://www.w3.org/2000/svg";
const views = {};

function addCamera(camera) {
  const box = document.createElement("div");
  box.className = "camera";
  box.innerHTML = `<div class="head"><b></b><span class="badge"></span><span class="since">` +
                  `</span><span class="transport"></span></div><div class="view">` +
                  `<img alt="live"><video muted autoplay playsinline hidden></video><svg></svg>` +
                  `<div class="placeholder"></div></div><div class="stats"></div>`;
  box.querySelector("b").textContent = camera.name;
  document.getElementById("cameras").appendChild(box);
  views[camera.name] = { box, img: box.querySelector("img"), video: box.querySelector("video"),
                         transport: box.querySelector(".transport"), svg: box.querySelector("svg"),
                         badge: box.querySelector(".badge"), since: box.querySelector(".since"),
                         placeholder: box.querySelector(".placeholder"),
                         stats: box.querySelector(".stats"),
                         width: camera.width, height: camera.height, state: "" };
  if (camera.status && camera.status.following !== undefined)
    addControls(views[camera.name], camera.name);
  if (camera.status) showStream(camera.status, 0);
  else setState(views[camera.name], "live", null);
  showDetections({ stream: camera.name, detections: camera.detections });
}

// live, no-video, offline, or connecting: waiting for the device (with
// since when). Not live: a placeholder saying why, never a broken image or
// a stale tag box; live again: the picture reconnects.
const stateKinds = { "live": "live", "offline": "offline", "no-video": "novideo" };
const stateWhy = {
  "offline": "the device is off, out of range or gone; it is reconnected to when it is back",
  "no-video": "the device is logged in but sends no frames (its camera unplugged, or its " +
      "stream blocked); the camera is started again",
};
function setState(view, state, sinceUtc) {
  const kind = stateKinds[state] || "waiting";
  const since = sinceUtc ? new Date(sinceUtc) : null;
  const sinceText = since ? "since " + since.toLocaleTimeString() : "";
  view.badge.className = "badge " + kind;
  view.badge.textContent = state;
  view.since.textContent = sinceText;
  view.placeholder.textContent =
      stateWhy[state] ? `${state} ${sinceText}: ${stateWhy[state]}` : "waiting for device";
  if (view.state !== kind) {
    view.box.dataset.state = kind;
    if (kind === "live") {
      startPicture(view, view.box.querySelector("b").textContent);
    } else {
      stopPicture(view);
      view.svg.replaceChildren();
    }
    view.state = kind;
  }
}

// A frame the detector missed the tag in (about one in eight) does not
// blank the outline at once: it flickered off at 15 fps. Outlines stay up
// to this long after the last frame that had them.
const outlineHoldMs = 300;

function showDetections(event) {
  const view = views[event.stream];
  if (!view || view.state !== "live") return;
  const now = performance.now();
  if (!event.detections.length && now - (view.outlinedAt || -Infinity) < outlineHoldMs) return;
  if (event.detections.length) view.outlinedAt = now;
  const shown = view.webrtc ? { width: view.video.videoWidth, height: view.video.videoHeight }
                            : { width: view.img.naturalWidth, height: view.img.naturalHeight };
  const width = shown.width || view.width, height = shown.height || view.height;
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

function showStream(stream, askedAt) {
  const view = views[stream.name];
  if (!view) return;
  setState(view, stream.state, stream.state_since_utc);
  showControls(view, stream, askedAt);
  view.stats.textContent = `${stream.fps.toFixed(1)} fps  ` +
      `loss ${stream.loss_percent.toFixed(1)} %  ${Math.round(stream.kbps)} kbit/s  ` +
      `battery ${stream.battery_v.toFixed(2)} V` +
      (stream.status_stale ? ` (stale, ${Math.round(stream.status_age_ms / 1000)} s old)` : "") +
      controlText(stream) + positionText(stream.position);
}

function showStatus(status, askedAt) {
  for (const stream of status.streams) {
    showStream(stream, askedAt);
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
  const askedAt = performance.now();
  showStatus(await (await fetch("/api/status")).json(), askedAt);
}

// The finished segments from the recording index, by camera and by day
// (local time), newest first: the day's timeline, then each segment's start,
// duration, size, frames, download, delete (which the server allows only
// with the access token).
async function refresh() {
  const segments = await (await fetch("/api/recordings")).json();
  const groups = new Map();
  for (const segment of segments.reverse()) {
    const start = new Date(segment.start_utc);
    const key = `${segment.camera} · ${start.toLocaleDateString()}`;
    if (!groups.has(key)) groups.set(key, Object.assign([], { camera: segment.camera }));
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
    box.append(heading, dayTimelineOf(title, list.camera, list), table);
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


function start() {
  // Built before the page's load event, so a screenshot at load shows them.
  const initial = INITIAL_STATE;
  webrtcOffered = initial.webrtc;
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
  startFleet();
}
start();
