// Each camera's day as one timeline across its finished segments (the
// recording index): the segments as blocks, an outage as the gap between
// two, the detections and commands of their sidecars as ticks. A click
// plays from that moment on, across the segments; a drag selects a range to
// export (GET /api/export) as one file.

const sidecars = new Map();  // file → its lines: a finished segment's never change
const dayRows = { segments: [4, 16], tags: [24, 8], commands: [36, 8] };
const dayLeft = 70, dayRight = 8, dayHeight = 62;
// A gap between two segments longer than this is an outage (the camera
// away), not the recorder's cut from one file to the next.
const outageMs = 1000;

async function sidecarOf(segment) {
  if (!sidecars.has(segment.file)) {
    const response = await fetch(sidecarUrl(segment));
    sidecars.set(segment.file, response.ok ? parseJsonLines(await response.text()) : []);
  }
  return sidecars.get(segment.file);
}

const clock = ms => new Date(ms).toLocaleTimeString();

class DayTimeline {
  constructor(camera) {
    this.camera = camera;
    this.segments = [];  // oldest first, each with its start and end (ms since the epoch)
    this.selection = null;  // [from, to], ms
    this.element = document.createElement("div");
    this.element.className = "day";
    this.canvas = document.createElement("canvas");
    this.canvas.className = "day-timeline";
    this.range = document.createElement("div");
    this.range.className = "range";
    this.element.append(this.canvas, this.range);
    this.canvas.addEventListener("pointerdown", e => this.press(e));
    this.canvas.addEventListener("pointermove", e => this.move(e));
    this.canvas.addEventListener("pointerup", e => this.release(e));
    this.showRange();
  }

  async update(segments) {
    this.segments = segments.map(s => ({ ...s, begins: s.start.getTime(),
                                         ends: s.start.getTime() + s.duration_s * 1000 }))
                            .sort((a, b) => a.begins - b.begins);
    this.first = this.segments[0].begins;
    this.last = Math.max(...this.segments.map(s => s.ends));
    this.draw();
    await Promise.all(this.segments.map(sidecarOf));
    this.draw();
  }

  span() { return Math.max(1, this.canvas.clientWidth - dayLeft - dayRight); }
  xOf(ms) { return dayLeft + (ms - this.first) / Math.max(1, this.last - this.first) * this.span(); }
  timeAt(x) {
    const fraction = Math.max(0, Math.min(1, (x - dayLeft) / this.span()));
    return this.first + fraction * (this.last - this.first);
  }

  draw() {
    const width = this.canvas.clientWidth;
    const g = timelineCanvas(this.canvas, dayHeight, dayRows);
    const [top, rowHeight] = dayRows.segments;
    this.segments.forEach((segment, i) => {
      const next = this.segments[i + 1];
      if (next && next.begins - segment.ends > outageMs) {
        g.fillStyle = "#5c1f1f";  // the outage
        g.fillRect(this.xOf(segment.ends), top, this.xOf(next.begins) - this.xOf(segment.ends),
                   rowHeight);
      }
      g.fillStyle = i % 2 ? "#5a8fd8" : "#3f6fb5";
      g.fillRect(this.xOf(segment.begins), top,
                 Math.max(1, this.xOf(segment.ends) - this.xOf(segment.begins)), rowHeight);
    });
    const tick = (ms, row, colour) => {
      const [rowTop, height] = dayRows[row];
      g.fillStyle = colour;
      g.fillRect(Math.round(this.xOf(ms)), rowTop, 1, height);
    };
    for (const segment of this.segments)
      for (const line of sidecars.get(segment.file) || []) {
        const ms = segment.begins + (line.pts || 0) / 1e6;
        if (line.type === "detections" && line.detections.length) tick(ms, "tags", "#00c853");
        const steering = line["steering-pulse"], throttle = line["throttle-pulse"];
        if (line.type === "control" && (steering !== 1500 || throttle !== 1500))
          tick(ms, "commands", "#ffd54f");
        if (line.type === "drive") tick(ms, "commands", "#4fc3f7");
      }
    if (this.selection) {
      const [from, to] = this.selection;
      g.fillStyle = "rgba(255, 255, 255, 0.18)";
      g.fillRect(this.xOf(from), 0, Math.max(1, this.xOf(to) - this.xOf(from)), 46);
    }
    g.fillStyle = "#aab";
    g.fillText(clock(this.first), dayLeft, dayHeight - 4);
    const end = clock(this.last);
    g.fillText(end, width - dayRight - g.measureText(end).width, dayHeight - 4);
  }

  press(event) {
    this.canvas.setPointerCapture(event.pointerId);
    this.drag = { x: event.offsetX, from: this.timeAt(event.offsetX) };
  }

  move(event) {
    if (!this.drag || Math.abs(event.offsetX - this.drag.x) < 4) return;
    const at = this.timeAt(event.offsetX);
    this.selection = [Math.min(this.drag.from, at), Math.max(this.drag.from, at)];
    this.draw();
  }

  release(event) {
    if (!this.drag) return;
    const clicked = Math.abs(event.offsetX - this.drag.x) < 4;
    const at = this.drag.from;
    this.drag = null;
    if (clicked) return this.play(at);
    this.showRange();
  }

  // From the moment on, the segment that holds it and those after; a moment
  // in an outage plays from the next segment.
  play(ms) {
    const i = this.segments.findIndex(s => s.ends > ms);
    if (i < 0) return;
    const segment = this.segments[i];
    openPlayer(segment, Math.max(0, (ms - segment.begins) / 1000), this.segments.slice(i + 1));
  }

  showRange() {
    this.range.replaceChildren();
    if (!this.selection) {
      this.range.textContent = "click to play from a moment; drag to select a range to export";
      return;
    }
    const [from, to] = this.selection.map(ms => new Date(Math.round(ms)));
    this.range.append(`${clock(from)} – ${clock(to)} (${((to - from) / 1000).toFixed(1)} s) export: `);
    // MP4 carries H.264 only: offered for the recordings made as MP4.
    const formats = this.segments.some(s => s.file.endsWith(".mp4")) ? ["mp4", "mkv", "mcap"]
                                                                     : ["mkv", "mcap"];
    for (const format of formats) {
      const link = document.createElement("a");
      link.className = "export";
      link.dataset.format = format;
      link.download = "";
      link.href = "/api/export?" + new URLSearchParams({ camera: this.camera,
          start: from.toISOString(), end: to.toISOString(), format });
      link.textContent = format;
      this.range.append(link, " ");
    }
    const clear = document.createElement("button");
    clear.textContent = "clear";
    clear.addEventListener("click", () => { this.selection = null; this.showRange(); this.draw(); });
    this.range.append(clear);
  }
}

// The day's timeline of a group of segments ("camera · day"), kept across
// refreshes so that a selection survives them.
const dayTimelines = new Map();
function dayTimelineOf(key, camera, segments) {
  if (!dayTimelines.has(key)) dayTimelines.set(key, new DayTimeline(camera));
  const timeline = dayTimelines.get(key);
  timeline.update(segments);
  return timeline.element;
}
