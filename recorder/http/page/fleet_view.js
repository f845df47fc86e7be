// The fleet (wirc-recorder --fleet, docs/fleet.md): every recorder the
// broker knows and its cameras, each with its vehicle, state, fps, battery
// and a live picture. The pictures come from each recorder directly (its
// snapshot.jpg, about once a second, with its token in an Authorization
// header: CORS), so no video crosses this recorder. The token is this
// page's own unless a recorder refuses it; then one for that recorder is
// asked for here and kept in this browser.

const fleetViews = new Map();  // recorder id → {box, cameras: Map(name → view)}
const fleetPictureMs = 1000;

function fleetToken(recorderId) {
  const own = (document.cookie.match(/(?:^|; )wircam_token=([^;]*)/) || [])[1];
  return localStorage.getItem("wircam-fleet-token:" + recorderId) || own || "";
}

function fleetRecorderView(recorder) {
  let view = fleetViews.get(recorder.id);
  if (view) return view;
  const box = document.createElement("div");
  box.className = "fleet-recorder";
  box.dataset.id = recorder.id;
  box.innerHTML = `<div class="head"><b></b><span class="badge"></span><span class="since">` +
                  `</span><span class="transport"></span></div><div class="fleet-token" hidden>` +
                  `<input type="password" placeholder="its access token"><button>use</button>` +
                  `</div><div class="fleet-cameras"></div>`;
  const input = box.querySelector(".fleet-token input");
  box.querySelector(".fleet-token button").addEventListener("click", () => {
    localStorage.setItem("wircam-fleet-token:" + recorder.id, input.value.trim());
    box.querySelector(".fleet-token").hidden = true;
  });
  document.getElementById("fleet-recorders").appendChild(box);
  view = { box, cameras: new Map() };
  fleetViews.set(recorder.id, view);
  return view;
}

function fleetCameraView(recorderView, name) {
  let view = recorderView.cameras.get(name);
  if (view) return view;
  const box = document.createElement("div");
  box.className = "fleet-camera";
  box.dataset.camera = name;
  box.innerHTML = `<div class="head"><b></b><span class="badge"></span></div>` +
                  `<img alt="live picture"><div class="stats"></div>`;
  box.querySelector("b").textContent = name;
  recorderView.box.querySelector(".fleet-cameras").appendChild(box);
  view = { box, img: box.querySelector("img"), busy: false, shownAt: 0 };
  recorderView.cameras.set(name, view);
  return view;
}

function showFleetRecorder(recorder) {
  const view = fleetRecorderView(recorder);
  const head = view.box.querySelector(".head");
  head.querySelector("b").textContent = recorder.host;
  const badge = head.querySelector(".badge");
  badge.className = "badge " + (recorder.online ? "live" : "offline");
  badge.textContent = recorder.online ? "online" : "offline";
  head.querySelector(".since").textContent =
      recorder.online ? "" : "last seen " + new Date(recorder.last_seen_utc).toLocaleString();
  head.querySelector(".transport").textContent = `${recorder.mqtt_prefix} · ${recorder.version}`;
  view.box.dataset.online = recorder.online;
  const names = new Set();
  for (const camera of recorder.cameras) {
    names.add(camera.name);
    const cameraView = fleetCameraView(view, camera.name);
    const state = recorder.online ? camera.state : "unknown";
    cameraView.box.dataset.state = state;
    const cameraBadge = cameraView.box.querySelector(".badge");
    cameraBadge.className = "badge " + (stateKinds[state] || "waiting");
    cameraBadge.textContent = state;
    const status = camera.status || {};
    const vehicle = camera.vehicle ? `${camera.vehicle.name} (${camera.vehicle.serial})` : "vehicle ?";
    cameraView.box.querySelector(".stats").textContent =
        `${vehicle} · ${(status.fps || 0).toFixed(1)} fps · ` +
        `${status.battery_v ? status.battery_v.toFixed(2) + " V" : "battery ?"}`;
    if (state === "live") fetchFleetPicture(recorder, camera.name, cameraView, view);
  }
  for (const [name, cameraView] of view.cameras)
    if (!names.has(name)) {
      cameraView.box.remove();
      view.cameras.delete(name);
    }
}

// The camera's newest JPEG from its own recorder, at most once a second.
async function fetchFleetPicture(recorder, name, view, recorderView) {
  if (view.busy || performance.now() - view.shownAt < fleetPictureMs || !recorder.urls.http) return;
  view.busy = true;
  try {
    const token = fleetToken(recorder.id);
    const response = await fetch(
        `${recorder.urls.http}api/cameras/${encodeURIComponent(name)}/snapshot.jpg`,
        { headers: token ? { Authorization: "Bearer " + token } : {}, cache: "no-store" });
    recorderView.box.querySelector(".fleet-token").hidden = response.status !== 401;
    if (!response.ok) return;
    const previous = view.img.src;
    view.img.src = URL.createObjectURL(await response.blob());
    if (previous.startsWith("blob:")) URL.revokeObjectURL(previous);
    view.shownAt = performance.now();
  } catch (error) {
    view.box.dataset.state = "unreachable";  // offline, or its certificate not trusted here
  } finally {
    view.busy = false;
  }
}

async function refreshFleet() {
  const response = await fetch("/api/fleet");
  if (!response.ok) return false;  // not a fleet recorder
  const fleet = await response.json();
  document.getElementById("fleet").hidden = false;
  const ids = new Set(fleet.recorders.map(r => r.id));
  for (const [id, view] of fleetViews)
    if (!ids.has(id)) {
      view.box.remove();
      fleetViews.delete(id);
    }
  fleet.recorders.forEach(showFleetRecorder);
  return true;
}

async function startFleet() {
  if (await refreshFleet()) setInterval(refreshFleet, fleetPictureMs);
}
