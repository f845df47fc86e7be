// The page wirc-recorder's web server shows at "/": every camera live as
// MJPEG (the camera's own frames, not re-encoded), the AprilTags found in
// them drawn over the picture from the /api/events stream, the status and
// the recordings. Self-contained: no scripts from elsewhere. The server
// puts the cameras and their last detections in place of INITIAL_STATE, so
// the first picture already carries its overlay.
#pragma once

namespace wircam::recorder {

inline constexpr const char kLiveViewPage[] = R"html(<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>wirc-recorder</title>
<meta name="viewport" content="width=device-width, initial-scale=1">
<style>
body { background: #15171a; color: #e8e8e8; font: 14px sans-serif; margin: 16px; }
h1 { font-size: 20px; margin: 0 0 12px; } h2 { font-size: 16px; }
.camera { display: inline-block; margin: 0 16px 16px 0; vertical-align: top; }
.view { position: relative; display: inline-block; line-height: 0; background: #000; }
.view img { display: block; max-width: 100%; min-width: 160px; min-height: 120px; }
.view svg { position: absolute; left: 0; top: 0; width: 100%; height: 100%; }
.tag { fill: none; stroke: #00ff00; stroke-width: 3; }
.label { fill: #00ff00; font: bold 18px sans-serif; }
.stats { margin-top: 6px; color: #aab; font-family: monospace; }
a { color: #8cf; } td { padding: 2px 12px 2px 0; }
</style></head>
<body>
<h1>wirc-recorder</h1>
<div id="cameras"></div>
<h2>Recordings</h2>
<table id="recordings"></table>
<script>
"use strict";
const svgNs = "http://www.w3.org/2000/svg";
const views = {};

function addCamera(camera) {
  const box = document.createElement("div");
  box.className = "camera";
  box.innerHTML = `<div><b></b></div><div class="view"><img alt="live"><svg></svg></div>` +
                  `<div class="stats"></div>`;
  box.querySelector("b").textContent = camera.name;
  box.querySelector("img").src = "/live/" + encodeURIComponent(camera.name) + ".mjpg";
  document.getElementById("cameras").appendChild(box);
  views[camera.name] = { img: box.querySelector("img"), svg: box.querySelector("svg"),
                         stats: box.querySelector(".stats"),
                         width: camera.width, height: camera.height };
  showDetections({ stream: camera.name, detections: camera.detections });
}

function showDetections(event) {
  const view = views[event.stream];
  if (!view) return;
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

function showStatus(status) {
  for (const stream of status.streams) {
    const view = views[stream.name];
    if (!view) continue;
    view.stats.textContent = `${stream.frames} frames  ${stream.fps.toFixed(1)} fps  ` +
        `loss ${stream.loss_percent.toFixed(1)} %  ${Math.round(stream.kbps)} kbit/s  ` +
        `battery ${stream.battery_v.toFixed(2)} V` +
        (stream.status_stale ? ` (stale, ${Math.round(stream.status_age_ms / 1000)} s old)` : "");
  }
}

async function refresh() {
  const status = await (await fetch("/api/status")).json();
  showStatus(status);
  const files = await (await fetch("/recordings")).json();
  const table = document.getElementById("recordings");
  table.replaceChildren();
  for (const file of files) {
    const row = table.insertRow();
    const link = document.createElement("a");
    link.href = "/recordings/" + encodeURIComponent(file.name);
    link.textContent = file.name;
    row.insertCell().appendChild(link);
    row.insertCell().textContent = (file.bytes / 1e6).toFixed(1) + " MB";
    row.insertCell().textContent = file.recording ? "recording" : "";
  }
}

function start() {
  // Built before the page's load event, so a screenshot at load shows them.
  const initial = INITIAL_STATE;
  initial.cameras.forEach(addCamera);
  const events = new EventSource("/api/events");
  events.addEventListener("detections", e => showDetections(JSON.parse(e.data)));
  refresh();
  setInterval(refresh, 2000);
}
start();
</script>
</body></html>
)html";

}  // namespace wircam::recorder
