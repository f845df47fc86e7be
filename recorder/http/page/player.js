// `following`: the segments that play on after this one (a day's timeline).
const player = { file: "", duration: 0, position: 0, abort: null, lines: [], objectUrl: "",
                 following: [] };

// A sidecar's text (JSON Lines) as objects; a line that does not parse is left out.
const parseJsonLines = text => text.split("\n").filter(l => l).flatMap(l => {
  try { return [JSON.parse(l)]; } catch (e) { return []; }
});
const sidecarUrl = segment => segment.url.replace(/\.(mkv|mp4)$/, ".jsonl");

// The end of a segment: on to the next one of the day, if any.
function playedToTheEnd() {
  if (player.following.length)
    return openPlayer(player.following[0], 0, player.following.slice(1));
  document.getElementById("playback-time").textContent += "  (end)";
}

function indexOfBytes(bytes, pattern, from) {
  outer: for (let i = from; i + pattern.length <= bytes.length; ++i) {
    for (let j = 0; j < pattern.length; ++j) if (bytes[i + j] !== pattern[j]) continue outer;
    return i;
  }
  return -1;
}

// multipart/x-mixed-replace as the server writes it: "--boundary", headers
// with Content-Length and X-Position, a blank line, the JPEG, CRLF.
async function readParts(response, onPart) {
  const reader = response.body.getReader();
  const headerEnd = [13, 10, 13, 10];
  let buffer = new Uint8Array(0);
  for (;;) {
    const { value, done } = await reader.read();
    if (done) return;
    const joined = new Uint8Array(buffer.length + value.length);
    joined.set(buffer);
    joined.set(value, buffer.length);
    buffer = joined;
    for (;;) {
      const end = indexOfBytes(buffer, headerEnd, 0);
      if (end < 0) break;
      const headers = new TextDecoder().decode(buffer.subarray(0, end));
      const length = Number((/Content-Length: *(\d+)/i.exec(headers) || [])[1]);
      const position = Number((/X-Position: *([\d.]+)/i.exec(headers) || [])[1]);
      if (buffer.length < end + 4 + length + 2) break;
      onPart(buffer.slice(end + 4, end + 4 + length), position);
      buffer = buffer.slice(end + 4 + length + 2);
    }
  }
}

function showPosition(position) {
  player.position = position;
  document.getElementById("playback-time").textContent =
      `${position.toFixed(1)} / ${player.duration.toFixed(1)} s`;
  drawTimeline();
}

async function playFrom(seconds) {
  if (player.abort) player.abort.abort();
  const video = document.getElementById("playback-video");
  if (player.file.endsWith(".mp4")) {
    video.currentTime = seconds;
    video.play();
    return;
  }
  const abort = new AbortController();
  player.abort = abort;
  const image = document.getElementById("playback-image");
  try {
    const response = await fetch(`/play/${encodeURIComponent(player.file)}.mjpg?from=${seconds}`,
                                 { signal: abort.signal });
    if (!response.ok) {
      document.getElementById("playback-time").textContent = (await response.json()).error;
      return;
    }
    await readParts(response, (jpeg, position) => {
      const url = URL.createObjectURL(new Blob([jpeg], { type: "image/jpeg" }));
      image.src = url;
      if (player.objectUrl) URL.revokeObjectURL(player.objectUrl);
      player.objectUrl = url;
      showPosition(position);
    });
    if (player.abort === abort) playedToTheEnd();
  } catch (e) {
    if (e.name !== "AbortError") document.getElementById("playback-time").textContent = e.message;
  }
}

// Plays `segment` from `from` seconds, then `following`.
async function openPlayer(segment, from = 0, following = []) {
  const box = document.getElementById("player");
  const continuing = !box.hidden && player.following[0] === segment;
  box.hidden = false;
  player.following = following;
  player.file = segment.file;
  player.duration = segment.duration_s;
  player.position = 0;
  player.lines = [];
  document.getElementById("player-title").textContent = segment.file;
  const mp4 = segment.file.endsWith(".mp4");
  const video = document.getElementById("playback-video");
  const image = document.getElementById("playback-image");
  video.hidden = !mp4;
  image.hidden = mp4;
  if (mp4) {
    video.src = segment.url;
    video.ontimeupdate = () => showPosition(video.currentTime);
    video.onended = playedToTheEnd;
  } else {
    video.removeAttribute("src");
  }
  if (!continuing) box.scrollIntoView();
  const response = await fetch(sidecarUrl(segment));
  if (response.ok) player.lines = parseJsonLines(await response.text());
  drawTimeline();
  playFrom(from);
}

function closePlayer() {
  if (player.abort) player.abort.abort();
  document.getElementById("playback-video").pause();
  document.getElementById("player").hidden = true;
  player.file = "";
  player.following = [];
}

// The timeline's rows (top, height) and its margins, in CSS pixels.
const timelineRows = { battery: [4, 30], tags: [38, 10], commands: [54, 10],
                       positions: [70, 10], events: [86, 10] };
const timelineLeft = 70, timelineRight = 8;
const timelineSpan = canvas => canvas.clientWidth - timelineLeft - timelineRight;

// A timeline's canvas at the screen's resolution, cleared, its rows
// ({name: [top, height]}) labelled on the left; its 2D context.
function timelineCanvas(canvas, height, rows) {
  const scale = window.devicePixelRatio || 1;
  canvas.width = canvas.clientWidth * scale;
  canvas.height = height * scale;
  const g = canvas.getContext("2d");
  g.scale(scale, scale);
  g.fillStyle = "#0d0f12";
  g.fillRect(0, 0, canvas.clientWidth, height);
  g.font = "11px sans-serif";
  g.fillStyle = "#889";
  for (const [name, [top, rowHeight]] of Object.entries(rows))
    g.fillText(name, 4, top + rowHeight / 2 + 4);
  return g;
}

// Each telemetry line at its time in the segment (pts, ns).
function drawTimeline() {
  const canvas = document.getElementById("timeline");
  const width = canvas.clientWidth, height = 104;
  const g = timelineCanvas(canvas, height, timelineRows);
  const span = timelineSpan(canvas);
  const x = seconds => timelineLeft + Math.min(1, seconds / (player.duration || 1)) * span;
  const at = line => (line.pts || 0) / 1e9;
  const tick = (line, row, colour) => {
    const [top, rowHeight] = timelineRows[row];
    g.fillStyle = colour;
    g.fillRect(Math.round(x(at(line))), top, 2, rowHeight);
  };
  const battery = player.lines.filter(l => l["battery-v"] !== undefined);
  if (battery.length) {
    const volts = battery.map(l => l["battery-v"]);
    const low = Math.min(...volts) - 0.05, high = Math.max(...volts) + 0.05;
    const [top, rowHeight] = timelineRows.battery;
    g.strokeStyle = "#ffb74d";
    g.beginPath();
    battery.forEach((l, i) => {
      const y = top + rowHeight - (l["battery-v"] - low) / (high - low) * rowHeight;
      i ? g.lineTo(x(at(l)), y) : g.moveTo(x(at(l)), y);
    });
    g.stroke();
    g.fillStyle = "#ffb74d";
    g.fillText(`${volts[volts.length - 1].toFixed(2)} V`, width - 48, 14);
  }
  for (const line of player.lines) {
    if (line.type === "detections" && line.detections.length) tick(line, "tags", "#00c853");
    const steering = line["steering-pulse"], throttle = line["throttle-pulse"];
    if (line.type === "control" && (steering !== 1500 || throttle !== 1500))
      tick(line, "commands", "#ffd54f");
    if (line.type === "drive") tick(line, "commands", "#4fc3f7");
    if (line.type === "position") tick(line, "positions", "#ba68c8");
    if (line.type === "position-stale") tick(line, "positions", "#777");
    if (line.type === "session" || line.type === "command") tick(line, "events", "#ef5350");
  }
  g.fillStyle = "#fff";
  g.fillRect(Math.round(x(player.position)) - 1, 0, 2, height);
}

function seekOnTimeline(event) {
  const canvas = document.getElementById("timeline");
  const fraction = (event.offsetX - timelineLeft) / timelineSpan(canvas);
  if (fraction < 0 || fraction > 1 || !player.file) return;
  const seconds = Math.max(0, Math.min(player.duration - 0.1, fraction * player.duration));
  showPosition(seconds);
  playFrom(seconds);
}

document.getElementById("timeline").addEventListener("click", seekOnTimeline);
document.getElementById("player-close").addEventListener("click", closePlayer);
