const kDrivePeriodMs = 100;
const keys = { ArrowUp: false, ArrowDown: false, ArrowLeft: false, ArrowRight: false };
let driving = null;  // { name, link, timer, seq, sent: Map(seq → time), view }
let drivingElsewhere = false;  // the fleet section drives a vehicle (fleet_view.js)

function addControls(view, name) {
  const box = document.createElement("div");
  box.className = "controls";
  box.innerHTML = `<button class="follow"></button>` +
      `<label>target <input class="target" type="number" min="-1" step="1" value="-1"></label>` +
      `<button class="set-target">set</button><button class="request">request control</button>` +
      `<button class="drive">drive</button><span class="drive-info"></span>` +
      `<div class="control-message"></div>`;
  view.box.appendChild(box);
  view.controls = box;
  const message = box.querySelector(".control-message");
  const post = async (path) => {
    const response = await fetch(`/api/cameras/${encodeURIComponent(name)}/${path}`,
                                 { method: "POST" });
    const answer = await response.json();
    if (!response.ok) {
      message.textContent = response.status === 403 ? "control needs the recorder started " +
          "with --http-token (and you signed in)" : answer.error;
      return false;
    }
    message.textContent = "";
    showControls(view, answer, performance.now());
    return true;
  };
  box.querySelector(".follow").addEventListener("click", () =>
      post(`follow?on=${view.following ? "false" : "true"}`));
  box.querySelector(".set-target").addEventListener("click", () =>
      post(`target?id=${Number(box.querySelector(".target").value)}`));
  box.querySelector(".request").addEventListener("click", () => post("request-control"));
  box.querySelector(".drive").addEventListener("click", async () => {
    if (driving && driving.name === name) return stopDriving("stopped");
    if (driving) stopDriving("driving another camera");
    // Following off first: it checks the right to control, and the car
    // should not follow again the moment the driver lets go.
    if (await post("follow?on=false")) startDriving(view, name);
  });
}

// Follow button and target from the camera's state (/api/status, /api/cameras),
// as it was at `askedAt` (performance.now()). A state asked for before the
// answer to a command came (a status poll on its way) is older than that
// answer: it would show the follow button as it was before the click.
function showControls(view, state, askedAt) {
  if (!view.controls || state.following === undefined) return;
  if (askedAt < (view.controlsAnsweredAt || 0)) return;
  view.controlsAnsweredAt = askedAt;
  view.following = state.following;
  view.controls.querySelector(".follow").textContent =
      state.following ? "following: on" : "following: off";
  view.controls.querySelector(".follow").classList.toggle("on", state.following);
}

function driveCommand() {
  let steering = (keys.ArrowLeft ? 1 : 0) - (keys.ArrowRight ? 1 : 0);
  let throttle = (keys.ArrowUp ? 1 : 0) - (keys.ArrowDown ? 1 : 0);
  for (const pad of navigator.getGamepads ? navigator.getGamepads() : []) {
    if (!pad || pad.axes.length < 2) continue;
    const dead = value => Math.abs(value) < 0.1 ? 0 : value;
    // Left stick: right is +x (steering is +left), up is -y.
    if (!steering) steering = -dead(pad.axes[0]);
    if (!throttle) throttle = -dead(pad.axes[1]);
  }
  return { steering: Math.max(-1, Math.min(1, steering)),
           throttle: Math.max(-1, Math.min(1, throttle)) };
}

// Where drive commands go: the WebRTC peer connection's data channel when
// the picture comes over WebRTC (unordered, no retransmits: a command never
// waits behind a lost one), otherwise a WebSocket. Either way the same
// messages, acks and dead-man.
function driveLink(view, name) {
  const channel = view.webrtc && view.webrtc.drive;
  if (channel && channel.readyState === "open") {
    const detach = new AbortController();
    const link = { kind: "WebRTC data channel", open: true, send: text => channel.send(text),
                   close: () => detach.abort() };
    channel.addEventListener("message", event => link.onmessage(event),
                             { signal: detach.signal });
    channel.addEventListener("close", () => link.onclose(), { signal: detach.signal });
    return link;
  }
  const scheme = location.protocol === "https:" ? "wss:" : "ws:";
  const socket = new WebSocket(`${scheme}//${location.host}/api/cameras/` +
                               `${encodeURIComponent(name)}/drive`);
  const link = { kind: "WebSocket", open: false, send: text => socket.send(text),
                 close: () => socket.close() };
  socket.onopen = () => { link.open = true; link.onopen(); };
  socket.onmessage = event => link.onmessage(event);
  socket.onclose = () => link.onclose();
  return link;
}

function startDriving(view, name) {
  const link = driveLink(view, name);
  const info = view.controls.querySelector(".drive-info");
  driving = { name, link, view, seq: 0, sent: new Map(), timer: 0 };
  view.controls.querySelector(".drive").classList.add("on");
  view.box.dataset.driving = "true";
  view.box.dataset.driveLink = link.kind;
  info.textContent = "connecting…";
  link.onopen = () => {
    info.textContent = `driving over ${link.kind}: arrow keys or gamepad`;
    // Every period, changed or not: the server's dead-man wants them.
    driving.timer = setInterval(() => {
      const command = { seq: ++driving.seq, ...driveCommand() };
      driving.sent.set(command.seq, performance.now());
      link.send(JSON.stringify(command));
    }, kDrivePeriodMs);
  };
  link.onmessage = event => {
    const answer = JSON.parse(event.data);
    if (answer.error) {
      info.textContent = answer.error;
      return;
    }
    const sentAt = driving && driving.sent.get(answer.ack);
    if (sentAt === undefined) return;
    driving.sent.delete(answer.ack);
    // Unordered: an old ack may come after a newer one; the older sends go.
    for (const seq of driving.sent.keys()) if (seq < answer.ack) driving.sent.delete(seq);
    const roundTrip = performance.now() - sentAt;
    info.textContent = `round trip ${roundTrip.toFixed(0)} ms` +
        (answer.obeyed ? "" : " — the vehicle does not obey: request control");
    info.dataset.roundTripMs = roundTrip.toFixed(1);
  };
  link.onclose = () => { if (driving && driving.link === link) stopDriving("disconnected"); };
  if (link.open) link.onopen();
}

function stopDriving(why) {
  if (!driving) return;
  const { link, view, timer } = driving;
  driving = null;
  clearInterval(timer);
  if (link.open) {
    try { link.send(JSON.stringify({ steering: 0, throttle: 0 })); } catch (e) { /* closed */ }
  }
  link.close();
  view.controls.querySelector(".drive").classList.remove("on");
  view.box.dataset.driving = "false";
  view.controls.querySelector(".drive-info").textContent = `not driving (${why})`;
}

for (const type of ["keydown", "keyup"])
  window.addEventListener(type, event => {
    if (!(driving || drivingElsewhere) || !(event.key in keys)) return;
    keys[event.key] = type === "keydown";
    event.preventDefault();
  });
// Keys released while the window had no focus never come up: let go of all.
window.addEventListener("blur", () => { for (const key in keys) keys[key] = false; });
document.addEventListener("visibilitychange", () => {
  if (document.hidden) stopDriving("the tab was hidden");
});
