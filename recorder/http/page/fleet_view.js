// The fleet (wirc-recorder --fleet, docs/fleet.md): every recorder the
// broker knows and its cameras, each with its vehicle, state, fps, battery
// and a live picture. The pictures come from each recorder directly (its
// snapshot.jpg, about once a second, with its token in an Authorization
// header: CORS), so no video crosses this recorder. The token is this
// page's own unless a recorder refuses it; then one for that recorder is
// asked for here and kept in this browser. Follow and drive go through
// this recorder and the broker to whichever recorder holds the vehicle.

const fleetViews = new Map();  // recorder id → {box, cameras: Map(name → view)}
const fleetPictureMs = 1000;
let fleetDriving = null;  // { serial, view, timer, busy }
// A fleet of more cameras than this opens with each recorder's cameras
// hidden: the page then asks only for the recorders the user opens (a
// view of the whole of 25,600 cameras is 8 MB, asked every second).
const fleetOpenUpTo = 64;

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
                  `</span><span class="count"></span><button class="fleet-open"></button>` +
                  `<span class="transport"></span></div><div class="fleet-token" hidden>` +
                  `<input type="password" placeholder="its access token"><button>use</button>` +
                  `</div><div class="fleet-cameras"></div>`;
  const input = box.querySelector(".fleet-token input");
  box.querySelector(".fleet-token button").addEventListener("click", () => {
    localStorage.setItem("wircam-fleet-token:" + recorder.id, input.value.trim());
    box.querySelector(".fleet-token").hidden = true;
  });
  document.getElementById("fleet-recorders").appendChild(box);
  view = { box, cameras: new Map(), open: undefined };
  box.querySelector(".fleet-open").addEventListener("click", () => {
    view.open = !view.open;
    refreshFleet();
  });
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
                  `<img alt="live picture"><div class="stats"></div>` +
                  `<div class="fleet-controls" hidden><button class="fleet-follow"></button>` +
                  `<button class="fleet-drive">drive</button>` +
                  `<span class="fleet-message"></span></div>`;
  box.querySelector("b").textContent = name;
  recorderView.box.querySelector(".fleet-cameras").appendChild(box);
  view = { box, img: box.querySelector("img"), busy: false, shownAt: 0, serial: "",
           following: false };
  box.querySelector(".fleet-follow").addEventListener("click", () =>
      commandFleetVehicle(view, `follow?on=${!view.following}`));
  box.querySelector(".fleet-drive").addEventListener("click", () => {
    if (fleetDriving && fleetDriving.view === view) return stopFleetDriving("stopped");
    startFleetDriving(view);
  });
  recorderView.cameras.set(name, view);
  return view;
}

function showFleetRecorderHead(recorder, view) {
  const head = view.box.querySelector(".head");
  head.querySelector("b").textContent = recorder.host;
  const badge = head.querySelector(".badge");
  badge.className = "badge " + (recorder.online ? "live" : "offline");
  badge.textContent = recorder.online ? "online" : "offline";
  head.querySelector(".since").textContent =
      recorder.online ? "" : "last seen " + new Date(recorder.last_seen_utc).toLocaleString();
  head.querySelector(".transport").textContent = `${recorder.mqtt_prefix} · ${recorder.version}`;
  head.querySelector(".count").textContent =
      `${recorder.cameras_live} of ${recorder.camera_count} cameras live`;
  head.querySelector(".fleet-open").textContent = view.open ? "hide cameras" : "show cameras";
  view.box.dataset.online = recorder.online;
  view.box.dataset.open = view.open;
}

function showFleetCameras(recorder, view) {
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
    showFleetControls(cameraView, camera, recorder.online);
    if (state === "live") fetchFleetPicture(recorder, camera.name, cameraView, view);
  }
  for (const [name, cameraView] of view.cameras)
    if (!names.has(name)) {
      if (fleetDriving && fleetDriving.view === cameraView) stopFleetDriving("its camera went");
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

// Follow and drive for a camera's vehicle, by its serial: this recorder
// hands them to the broker, and the recorder that holds the vehicle now
// applies them (docs/fleet.md), wherever it moved.
function showFleetControls(view, camera, online) {
  const serial = camera.vehicle && camera.vehicle.serial;
  const controls = view.box.querySelector(".fleet-controls");
  controls.hidden = !serial || !online;
  if (!serial) return;
  view.serial = serial;
  view.following = !!(camera.status && camera.status.following);
  const follow = controls.querySelector(".fleet-follow");
  follow.textContent = view.following ? "following: on" : "following: off";
  follow.classList.toggle("on", view.following);
}

async function commandFleetVehicle(view, command) {
  const message = view.box.querySelector(".fleet-message");
  try {
    const response = await fetch(
        `/api/fleet/vehicles/${encodeURIComponent(view.serial)}/${command}`, { method: "POST" });
    if (!response.ok) {
      message.textContent = (await response.json()).error;
      return false;
    }
    if (!fleetDriving || fleetDriving.view !== view) message.textContent = "";
    return true;
  } catch (error) {
    message.textContent = "this recorder did not answer";
    return false;
  }
}

// A command every period while driving, changed or not: the holding
// recorder's dead-man stops the vehicle 250 ms after the last.
async function startFleetDriving(view) {
  if (fleetDriving) stopFleetDriving("driving another vehicle");
  if (driving) stopDriving("driving a fleet vehicle");
  // Following off first, as the camera's own drive button does.
  if (!(await commandFleetVehicle(view, "follow?on=false"))) return;
  fleetDriving = { view, busy: false, timer: 0 };
  drivingElsewhere = true;
  view.box.dataset.driving = "true";
  view.box.querySelector(".fleet-drive").classList.add("on");
  view.box.querySelector(".fleet-message").textContent =
      `driving ${view.serial} through the broker: arrow keys or gamepad`;
  fleetDriving.timer = setInterval(async () => {
    const drive = fleetDriving;
    if (!drive || drive.busy) return;  // one on its way at a time
    drive.busy = true;
    const { steering, throttle } = driveCommand();
    await commandFleetVehicle(view, `drive?steering=${steering}&throttle=${throttle}`);
    drive.busy = false;
  }, kDrivePeriodMs);
}

function stopFleetDriving(why) {
  if (!fleetDriving) return;
  const { view, timer } = fleetDriving;
  fleetDriving = null;
  drivingElsewhere = false;
  clearInterval(timer);
  commandFleetVehicle(view, "drive?steering=0&throttle=0");
  view.box.dataset.driving = "false";
  view.box.querySelector(".fleet-drive").classList.remove("on");
  view.box.querySelector(".fleet-message").textContent = `not driving (${why})`;
}

document.addEventListener("visibilitychange", () => {
  if (document.hidden) stopFleetDriving("the tab was hidden");
});

// What the search box asks for: the recorders that have a match, each
// with its matching cameras only, the others hidden (the server searches:
// one request, whatever the fleet's size).
async function showFleetMatches(text) {
  const response = await fetch(`/api/fleet?match=${encodeURIComponent(text)}`);
  if (!response.ok) return response.status !== 404;
  const matched = (await response.json()).recorders;
  const ids = new Set(matched.map(r => r.id));
  for (const [id, view] of fleetViews)
    if (!ids.has(id)) {
      view.box.hidden = true;
      showFleetCameras({ cameras: [] }, view);
    }
  let found = 0;
  for (const recorder of matched) {
    const view = fleetRecorderView(recorder);
    view.box.hidden = false;
    showFleetRecorderHead(recorder, view);
    showFleetCameras(recorder, view);
    found += recorder.cameras.length;
  }
  document.getElementById("fleet").hidden = false;
  document.getElementById("fleet-found").textContent =
      found ? `${found} camera${found === 1 ? "" : "s"} found` : "no camera matches";
  return true;
}

// The recorders without their cameras, then the cameras of each recorder
// that is open, one request each; or, while the search box holds text,
// the cameras that match it.
async function refreshFleet() {
  const search = document.getElementById("fleet-search").value.trim();
  if (search) return showFleetMatches(search);
  const response = await fetch("/api/fleet?cameras=false");
  if (!response.ok) return false;  // not a fleet recorder
  const fleet = await response.json();
  document.getElementById("fleet").hidden = false;
  const ids = new Set(fleet.recorders.map(r => r.id));
  for (const [id, view] of fleetViews)
    if (!ids.has(id)) {
      view.box.remove();
      fleetViews.delete(id);
    }
  document.getElementById("fleet-found").textContent = "";
  const cameras = fleet.recorders.reduce((sum, r) => sum + r.camera_count, 0);
  await Promise.all(fleet.recorders.map(async recorder => {
    const view = fleetRecorderView(recorder);
    if (view.open === undefined) view.open = cameras <= fleetOpenUpTo;
    view.box.hidden = false;
    showFleetRecorderHead(recorder, view);
    if (!view.open) return showFleetCameras({ ...recorder, cameras: [] }, view);
    const one = await fetch(`/api/fleet?recorder=${encodeURIComponent(recorder.id)}`);
    if (!one.ok) return;  // gone meanwhile
    const [full] = (await one.json()).recorders;
    if (full && view.open) showFleetCameras(full, view);
  }));
  return true;
}

async function startFleet() {
  if (!(await refreshFleet())) return;
  let refreshing = false;  // a slow answer is not asked again over itself
  const refresh = async () => {
    if (refreshing) return;
    refreshing = true;
    try { await refreshFleet(); } finally { refreshing = false; }
  };
  setInterval(refresh, fleetPictureMs);
  // A search shows as it is typed, a pause after the last key.
  let typing = 0;
  document.getElementById("fleet-search").addEventListener("input", () => {
    clearTimeout(typing);
    typing = setTimeout(refresh, 250);
  });
}
