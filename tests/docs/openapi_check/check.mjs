// Validates docs/api/openapi.yaml with @apidevtools/swagger-parser, then
// starts wirc-sim and two wirc-recorder --http on loopback (ephemeral ports,
// a scratch folder) and checks the real answers of every endpoint and its
// main error paths against the document: the status is one it lists, the
// media type one it names, required headers are there, and JSON bodies
// validate against its schemas (Ajv, JSON Schema 2020-12 as OpenAPI 3.1).
//
//   node check.mjs OPENAPI.yaml BUILD_BIN_DIR
import { spawn } from "node:child_process";
import { mkdtempSync, rmSync, writeFileSync } from "node:fs";
import http from "node:http";
import net from "node:net";
import os from "node:os";
import path from "node:path";
import crypto from "node:crypto";

import SwaggerParser from "@apidevtools/swagger-parser";
import Ajv2020 from "ajv/dist/2020.js";
import addFormats from "ajv-formats";

const [specPath, binArgument] = process.argv.slice(2);
const binDir = binArgument && path.resolve(binArgument);
if (!specPath || !binDir) {
  console.error("usage: node check.mjs OPENAPI.yaml BUILD_BIN_DIR");
  process.exit(2);
}

const problems = [];
const checked = new Set();
function problem(text) {
  problems.push(text);
  console.error("FAIL " + text);
}

// --- the document ---------------------------------------------------------

await SwaggerParser.validate(specPath);
const api = await SwaggerParser.dereference(specPath);
if (!api.openapi.startsWith("3.1")) problem(`openapi is ${api.openapi}, not 3.1`);
const ajv = new Ajv2020({ allErrors: true, strict: true, strictTypes: false });
addFormats(ajv);
const validators = new Map();
function validatorOf(schema) {
  if (!validators.has(schema)) validators.set(schema, ajv.compile(schema));
  return validators.get(schema);
}

// The path template of the document that `urlPath` falls under.
const templates = Object.keys(api.paths).map((template) => {
  const pattern = template
    .split(/(\{[^}]+\})/)
    .map((part) => (part.startsWith("{") ? "[^/]+?" : part.replace(/[.*+?^$()|[\]\\]/g, "\\$&")))
    .join("");
  return { template, regex: new RegExp("^" + pattern + "$") };
});
function templateOf(urlPath) {
  const exact = templates.find((t) => t.template === urlPath);
  if (exact) return exact.template;
  return templates.find((t) => t.regex.test(urlPath))?.template;
}

const mediaType = (value) => (value || "").split(";")[0].trim().toLowerCase();

// Checks one answer against the document; returns the parsed JSON body, if any.
// `template` names the path of the document where the URL's own cannot
// (an encoded "/" that, decoded, matches no path).
function conform(label, method, url, answer, { expect, template: given } = {}) {
  const urlPath = decodeURIComponent(new URL(url).pathname);
  const template = given || templateOf(urlPath);
  const where = `${label}: ${method} ${urlPath} → ${answer.status}`;
  if (expect !== undefined && answer.status !== expect)
    problem(`${where}: expected ${expect} (${answer.body.toString().slice(0, 200)})`);
  if (!template) return problem(`${where}: no path of the document matches`);
  const operation = api.paths[template][method.toLowerCase()];
  if (!operation) return problem(`${where}: ${template} has no ${method}`);
  const response = operation.responses[String(answer.status)];
  if (!response) return problem(`${where}: status not documented for ${method} ${template}`);
  checked.add(`${method} ${template} ${answer.status}`);
  for (const [name, header] of Object.entries(response.headers || {}))
    if (header.required && answer.headers[name.toLowerCase()] === undefined)
      problem(`${where}: header ${name} missing`);
  const contents = response.content || {};
  if (answer.body.length === 0 && !answer.streamed) return undefined;
  const type = mediaType(answer.headers["content-type"]);
  if (!Object.keys(contents).length)
    return problem(`${where}: a ${type} body where the document has none`);
  const content = contents[type];
  if (!content) return problem(`${where}: ${type} is not one of ${Object.keys(contents)}`);
  if (type !== "application/json") return undefined;
  let body;
  try {
    body = JSON.parse(answer.body.toString());
  } catch (error) {
    return problem(`${where}: not JSON: ${error.message}`);
  }
  const validate = validatorOf(content.schema);
  if (!validate(body))
    problem(`${where}: ${ajv.errorsText(validate.errors)} in ${answer.body.toString().slice(0, 300)}`);
  return body;
}

// --- HTTP -------------------------------------------------------------------

// One request; with `until` the body is read only until until(body) is true
// (streams that never end), then the request is dropped.
function request(method, url, { headers = {}, body, until, timeout = 15000 } = {}) {
  return new Promise((resolve, reject) => {
    const request = http.request(url, { method, headers, agent: false }, (response) => {
      const chunks = [];
      let done = false;
      const finish = (streamed) => {
        if (done) return;
        done = true;
        clearTimeout(timer);
        resolve({ status: response.statusCode, headers: response.headers,
                  body: Buffer.concat(chunks), streamed });
      };
      response.on("data", (chunk) => {
        chunks.push(chunk);
        if (until && until(Buffer.concat(chunks))) {
          finish(true);
          request.destroy();
        }
      });
      response.on("end", () => finish(false));
      response.on("error", () => finish(true));
    });
    const timer = setTimeout(() => {
      request.destroy();
      reject(new Error(`${method} ${url}: no answer in ${timeout} ms`));
    }, timeout);
    request.on("error", (error) => {
      clearTimeout(timer);
      reject(error);
    });
    if (body !== undefined) {
      request.setHeader("Content-Length", Buffer.byteLength(body));
      request.write(body);
    }
    request.end();
  });
}

const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));
async function waitFor(what, condition, timeout = 30000) {
  const deadline = Date.now() + timeout;
  while (Date.now() < deadline) {
    const value = await condition();
    if (value) return value;
    await sleep(100);
  }
  throw new Error(`timed out waiting for ${what}`);
}

// --- processes --------------------------------------------------------------

const scratch = mkdtempSync(path.join(os.tmpdir(), "wircam-openapi-"));
const children = [];
function start(name, args) {
  // Ours from the build; others (the MQTT broker) from PATH.
  const program = name.startsWith("wirc-") ? path.join(binDir, name) : name;
  const child = spawn(program, args, {
    cwd: scratch,
    env: { ...process.env, GST_REGISTRY: path.join(scratch, "registry.bin") },
    stdio: ["ignore", "pipe", "pipe"],
  });
  child.output = "";
  child.stdout.on("data", (data) => (child.output += data));
  child.stderr.on("data", (data) => (child.output += data));
  children.push(child);
  return child;
}
function stopAll() {
  for (const child of children) if (child.exitCode === null) child.kill("SIGTERM");
}
process.on("exit", () => {
  for (const child of children) if (child.exitCode === null) child.kill("SIGKILL");
  rmSync(scratch, { recursive: true, force: true });
});

const token = crypto.randomBytes(16).toString("hex");
const bearer = { Authorization: `Bearer ${token}` };

let exitCode = 0;
try {
  const sim = start("wirc-sim", ["--port", "0", "--duration", "120"]);
  const simPort = await waitFor("wirc-sim's port",
    () => sim.output.match(/listening on 127\.0\.0\.1:(\d+)/)?.[1]);

  // A: with a token, following, WebRTC on, in a fleet on a real mosquitto.
  // B: no token, WebRTC off, no fleet.
  const brokerPort = await freePort();
  const broker = start("mosquitto", ["-p", String(brokerPort)]);
  // A's segment length comes from a config file, which a reload reads again.
  const configA = path.join(scratch, "a.ini");
  writeFileSync(configA, "[recorder]\nsegment=1\n");
  const a = start("wirc-recorder", ["--device", `127.0.0.1:${simPort}`, "--out", "a",
    "--config", configA, "--detect", "tag36h11", "--follow", "--http", "127.0.0.1:0",
    "--http-token", token, "--duration", "110", "--mqtt", `mqtt://127.0.0.1:${brokerPort}`,
    "--mqtt-prefix", "openapi/a", "--fleet"]);
  const b = start("wirc-recorder", ["--device", `127.0.0.1:${simPort}`, "--out", "b",
    "--segment", "1", "--http", ":0", "--webrtc", "off", "--duration", "110"]);
  const urlA = await waitFor("recorder A's URL", () => a.output.match(/live view at (http:\/\/\S+\/)/)?.[1]);
  const urlB = await waitFor("recorder B's URL", () => b.output.match(/live view at (http:\/\/\S+\/)/)?.[1]);

  const camerasA = await waitFor("a live camera", async () => {
    const answer = await request("GET", urlA + "api/cameras", { headers: bearer });
    const list = JSON.parse(answer.body.toString());
    return list.length && list[0].state === "live" ? list : null;
  });
  const camera = camerasA[0].name;
  const enc = encodeURIComponent;
  // Two finished segments: one to delete, one to play and export.
  const index = await waitFor("two finished segments", async () => {
    const answer = await request("GET", urlA + "api/recordings", { headers: bearer });
    const list = JSON.parse(answer.body.toString());
    return list.length >= 2 ? list : null;
  });

  async function check(label, method, url, options = {}) {
    const answer = await request(method, url, options);
    const body = conform(label, method, url, answer, options);
    return { ...answer, json: body };
  }

  // Page and sign-in
  await check("page without token", "GET", urlA, { expect: 401 });
  await check("page", "GET", urlA, { headers: bearer, expect: 200 });
  await check("index.html", "GET", urlA + "index.html", { headers: bearer, expect: 200 });
  await check("login", "GET", urlA + "login", { expect: 200 });

  // Status, with each way of giving the token
  const refused = await check("status without token", "GET", urlA + "api/status", { expect: 401 });
  if (!/Basic/.test(refused.headers["www-authenticate"] || ""))
    problem("401 without WWW-Authenticate: Basic");
  await check("status", "GET", urlA + "api/status", { headers: bearer, expect: 200 });
  await check("status, Basic", "GET", urlA + "api/status", {
    headers: { Authorization: "Basic " + Buffer.from(`viewer:${token}`).toString("base64") },
    expect: 200 });
  await check("status, cookie", "GET", urlA + "api/status", {
    headers: { Cookie: `a=1; wircam_token=${token}` }, expect: 200 });
  await check("status, wrong token", "GET", urlA + "api/status", {
    headers: { Authorization: "Bearer " + "x".repeat(32) }, expect: 401 });
  await check("cameras", "GET", urlA + "api/cameras", { headers: bearer, expect: 200 });
  await check("metrics", "GET", urlA + "metrics", { headers: bearer, expect: 200 });

  // Events: wait for a detection
  const events = await check("events", "GET", urlA + "api/events", {
    headers: bearer, expect: 200, until: (body) => /event: detections\ndata: .*\n\n/.test(body.toString()) });
  const data = events.body.toString().match(/event: detections\ndata: (.*)\n\n/)?.[1];
  if (!data) problem("no detections event on /api/events");
  else {
    const validate = validatorOf(api.components.schemas.DetectionsEvent);
    if (!validate(JSON.parse(data))) problem(`detections event: ${ajv.errorsText(validate.errors)}: ${data}`);
    else checked.add("event detections");
  }

  // Snapshot
  const snapshot = await check("snapshot", "GET", `${urlA}api/cameras/${enc(camera)}/snapshot.jpg`,
    { headers: bearer, expect: 200 });
  if (snapshot.body[0] !== 0xff || snapshot.body[1] !== 0xd8) problem("snapshot is not a JPEG");
  await check("snapshot, unknown", "GET", `${urlA}api/cameras/nope-cam0/snapshot.jpg`,
    { headers: bearer, expect: 404 });

  // Commands
  const command = (what) => `${urlA}api/cameras/${enc(camera)}/${what}`;
  await check("follow off", "POST", command("follow?on=false"), { headers: bearer, expect: 200 });
  await check("follow on", "POST", command("follow?on=true"), { headers: bearer, expect: 200 });
  await check("follow, bad", "POST", command("follow?on=maybe"), { headers: bearer, expect: 400 });
  await check("target", "POST", command("target?id=0"), { headers: bearer, expect: 200 });
  await check("target, bad", "POST", command("target?id=x"), { headers: bearer, expect: 400 });
  await check("request-control", "POST", command("request-control"), { headers: bearer, expect: 200 });
  await check("target, unknown", "POST", `${urlA}api/cameras/nope-cam0/target?id=1`,
    { headers: bearer, expect: 404 });
  await check("follow without token", "POST", command("follow?on=true"), { expect: 401 });
  // The same config again: nothing changes. One that does not validate: refused.
  await check("reload", "POST", urlA + "api/config/reload", { headers: bearer, expect: 200 });
  writeFileSync(configA, "[recorder]\nsegment=banana\n");
  await check("reload, invalid", "POST", urlA + "api/config/reload", { headers: bearer, expect: 400 });
  writeFileSync(configA, "[recorder]\nsegment=1\n");
  await check("reload without token", "POST", urlA + "api/config/reload", { expect: 401 });

  // Drive: the WebSocket and its refusals
  await check("drive, not a handshake", "GET", command("drive"), { headers: bearer, expect: 400 });
  await check("drive, unknown", "GET", `${urlA}api/cameras/nope-cam0/drive`, { headers: bearer, expect: 404 });
  await driveOverWebSocket(command("drive"));

  // WHEP
  const whep = command("whep");
  const offer = sdpOffer();
  const answer = await check("whep offer", "POST", whep, {
    headers: { ...bearer, "Content-Type": "application/sdp" }, body: offer, expect: 201 });
  const location = answer.headers.location;
  if (!/^\/api\/cameras\/[^/]+\/whep\/[^/]+$/.test(location || "")) problem(`whep Location ${location}`);
  if (!/a=end-of-candidates/.test(answer.body.toString())) problem("whep answer without end-of-candidates");
  if (location) {
    await check("whep delete", "DELETE", new URL(location, urlA).href, { headers: bearer, expect: 200 });
    await check("whep delete again", "DELETE", new URL(location, urlA).href, { headers: bearer, expect: 404 });
  }
  await check("whep, not sdp", "POST", whep, {
    headers: { ...bearer, "Content-Type": "text/plain" }, body: offer, expect: 415 });
  await check("whep, junk", "POST", whep, {
    headers: { ...bearer, "Content-Type": "application/sdp" }, body: "hello", expect: 400 });
  await check("whep, too big", "POST", whep, {
    headers: { ...bearer, "Content-Type": "application/sdp" }, body: "v=0\r\n" + "a=x\r\n".repeat(4000),
    expect: 413 });
  await check("whep, unknown", "POST", `${urlA}api/cameras/nope-cam0/whep`, {
    headers: { ...bearer, "Content-Type": "application/sdp" }, body: offer, expect: 404 });

  // Recordings
  await check("index", "GET", urlA + "api/recordings", { headers: bearer, expect: 200 });
  const files = await check("files", "GET", urlA + "recordings", { headers: bearer, expect: 200 });
  const [toDelete, toKeep] = index;
  await check("download", "GET", urlA + "recordings/" + enc(toKeep.file), { headers: bearer, expect: 200 });
  await check("download, range", "GET", urlA + "recordings/" + enc(toKeep.file),
    { headers: { ...bearer, Range: "bytes=0-99" }, expect: 206 });
  await check("download sidecar", "GET",
    urlA + "recordings/" + enc(toKeep.file.replace(/\.mkv$/, ".jsonl")), { headers: bearer, expect: 200 });
  await check("download, unknown", "GET", urlA + "recordings/nope.mkv", { headers: bearer, expect: 404 });
  await check("index entry, GET", "GET", urlA + "api/recordings/" + enc(toKeep.file),
    { headers: bearer, expect: 405 });
  await check("delete", "DELETE", urlA + "api/recordings/" + enc(toDelete.file), { headers: bearer, expect: 200 });
  await check("delete again", "DELETE", urlA + "api/recordings/" + enc(toDelete.file),
    { headers: bearer, expect: 404 });
  // The segment being written, looked up just before its DELETE: with 1 s
  // segments it may still close in between (then it is deleted, 200, as any
  // finished one: the next one is tried).
  let tried = false;
  for (let attempt = 0; attempt < 5 && !tried; ++attempt) {
    const listed = attempt === 0 ? files.json
      : JSON.parse((await request("GET", urlA + "recordings", { headers: bearer })).body.toString());
    const open = listed.find((f) => f.recording && f.name.endsWith(".mkv"));
    if (!open) continue;
    const url = urlA + "api/recordings/" + enc(open.name);
    const answer = await request("DELETE", url, { headers: bearer });
    if (answer.status === 200) continue;
    conform("delete, being recorded", "DELETE", url, answer, { expect: 409 });
    tried = true;
  }
  if (!tried) problem("no segment being recorded could be tried: each finished before its DELETE");
  const another = await waitFor("a third finished segment", async () => {
    const later = await request("GET", urlA + "api/recordings", { headers: bearer });
    return JSON.parse(later.body.toString()).find((e) => e.file !== toKeep.file);
  });
  await check("delete by its download URL", "DELETE", urlA + "recordings/" + enc(another.file),
    { headers: bearer, expect: 200 });
  await check("delete without token", "DELETE", urlA + "api/recordings/" + enc(toKeep.file), { expect: 401 });

  // Live and playback streams
  await check("live", "GET", `${urlA}live/${enc(camera)}.mjpg`, {
    headers: bearer, expect: 200, until: (body) => body.includes(Buffer.from([0xff, 0xd9])) });
  await check("live, unknown", "GET", `${urlA}live/nope-cam0.mjpg`, { headers: bearer, expect: 404 });
  const play = await check("play", "GET", `${urlA}play/${enc(toKeep.file)}.mjpg?from=0.2`, {
    headers: bearer, expect: 200, until: (body) => /X-Position: \d+\.\d{3}/.test(body.toString("latin1")) });
  if (!/X-Position/.test(play.body.toString("latin1"))) problem("playback parts without X-Position");
  await check("play, bad from", "GET", `${urlA}play/${enc(toKeep.file)}.mjpg?from=abc`,
    { headers: bearer, expect: 400 });
  await check("play, unknown", "GET", `${urlA}play/nope.mkv.mjpg`, { headers: bearer, expect: 404 });

  // Export
  const exportUrl = (query) => `${urlA}api/export?${query}`;
  const exported = await check("export", "GET",
    exportUrl(`camera=${enc(camera)}&format=mkv&start=${enc(toKeep.start_utc)}`),
    { headers: bearer, expect: 200, timeout: 60000 });
  if (!/attachment; filename=/.test(exported.headers["content-disposition"] || ""))
    problem("export without Content-Disposition");
  await check("export mcap", "GET", exportUrl(`camera=${enc(camera)}&format=mcap`),
    { headers: bearer, expect: 200, timeout: 60000 });
  await check("export mp4 of JPEG", "GET", exportUrl(`camera=${enc(camera)}&format=mp4`),
    { headers: bearer, expect: 415, timeout: 60000 });
  await check("export, no camera", "GET", exportUrl("format=mkv"), { headers: bearer, expect: 400 });
  await check("export, bad format", "GET", exportUrl(`camera=${enc(camera)}&format=avi`),
    { headers: bearer, expect: 400 });
  await check("export, bad time", "GET", exportUrl(`camera=${enc(camera)}&format=mkv&start=yesterday`),
    { headers: bearer, expect: 400 });
  await check("export, end before start", "GET",
    exportUrl(`camera=${enc(camera)}&format=mkv&start=2026-11-24T15:00:00Z&end=2026-11-24T14:00:00Z`),
    { headers: bearer, expect: 400 });
  await check("export, unknown camera", "GET", exportUrl("camera=nope-cam0&format=mkv"),
    { headers: bearer, expect: 404 });
  await check("export, empty range", "GET",
    exportUrl(`camera=${enc(camera)}&format=mkv&start=2099-01-01T00:00:00Z`), { headers: bearer, expect: 404 });

  // The index narrowed, and the fleet (A's, of itself alone).
  await check("index of a vehicle", "GET", urlA + "api/recordings?vehicle=SIM0001&day=" +
    toKeep.start_utc.slice(0, 10), { headers: bearer, expect: 200 });
  await check("index, bad day", "GET", urlA + "api/recordings?day=2026-02-30", { headers: bearer, expect: 400 });
  await waitFor("A in its fleet, with its vehicle", async () => {
    const fleet = (await check("fleet", "GET", urlA + "api/fleet", { headers: bearer, expect: 200 })).json;
    return fleet?.recorders?.[0]?.online && fleet.recorders[0].cameras[0]?.vehicle;
  });
  const history = (await check("fleet recordings", "GET", urlA + "api/fleet/recordings?vehicle=SIM0001",
    { headers: bearer, expect: 200 })).json;
  if (!history?.recordings?.length || !history.recordings[0].url.startsWith(urlA))
    problem(`fleet recordings: none, or not at A: ${JSON.stringify(history).slice(0, 300)}`);
  await check("fleet recordings, bad day", "GET", urlA + "api/fleet/recordings?day=tuesday",
    { headers: bearer, expect: 400 });
  await check("fleet, no token", "GET", urlA + "api/fleet", { expect: 401 });
  const counts = (await check("fleet, counts only", "GET", urlA + "api/fleet?cameras=false",
    { headers: bearer, expect: 200 })).json;
  const idA = counts?.recorders?.[0]?.id;
  if (!idA || counts.recorders[0].cameras !== undefined || counts.recorders[0].camera_count !== 1)
    problem(`fleet?cameras=false: ${JSON.stringify(counts).slice(0, 300)}`);
  const one = (await check("fleet, one recorder", "GET", `${urlA}api/fleet?recorder=${enc(idA)}`,
    { headers: bearer, expect: 200 })).json;
  if (one?.recorders?.length !== 1 || one.recorders[0].cameras?.length !== 1)
    problem(`fleet?recorder=: ${JSON.stringify(one).slice(0, 300)}`);
  await check("fleet, no such recorder", "GET", urlA + "api/fleet?recorder=nope",
    { headers: bearer, expect: 404 });
  await check("fleet, bad cameras", "GET", urlA + "api/fleet?cameras=maybe",
    { headers: bearer, expect: 400 });
  // Another recorder's page reads these across origins (CORS).
  const origin = { Origin: "http://other-recorder.example:8080" };
  for (const url of [urlA + "api/fleet", urlA + "api/cameras", urlA + "api/status",
    `${urlA}api/cameras/${enc(camera)}/snapshot.jpg`]) {
    await check("preflight", "OPTIONS", url, {
      headers: { ...origin, "Access-Control-Request-Method": "GET",
                 "Access-Control-Request-Headers": "authorization" }, expect: 204 });
    const read = await request("GET", url, { headers: { ...origin, ...bearer } });
    if (read.headers["access-control-allow-origin"] !== "*")
      problem(`GET ${new URL(url).pathname} from another origin: no Access-Control-Allow-Origin`);
  }
  const closed = await request("OPTIONS", urlA + "api/recordings", { headers: origin });
  if (closed.headers["access-control-allow-origin"])
    problem("OPTIONS /api/recordings: allowed across origins, which the page does not need");
  await check("fleet recordings, no token", "GET", urlA + "api/fleet/recordings", { expect: 401 });
  await check("B fleet, not one", "GET", urlB + "api/fleet", { expect: 404 });
  await check("B fleet recordings, not one", "GET", urlB + "api/fleet/recordings", { expect: 404 });
  // A vehicle's commands through the broker, by its serial (A holds it).
  const vehicle = urlA + "api/fleet/vehicles/SIM0001/";
  await check("fleet follow", "POST", vehicle + "follow?on=true", { headers: bearer, expect: 202 });
  await check("fleet target", "POST", vehicle + "target?id=0", { headers: bearer, expect: 202 });
  await check("fleet drive", "POST", vehicle + "drive?steering=0&throttle=0",
    { headers: bearer, expect: 202 });
  await check("fleet drive, bad", "POST", vehicle + "drive?steering=left&throttle=0",
    { headers: bearer, expect: 400 });
  await check("fleet follow, no token", "POST", vehicle + "follow?on=true", { expect: 401 });
  await check("B fleet drive, not one", "POST", urlB + "api/fleet/vehicles/SIM0001/drive?steering=0&throttle=0",
    { expect: 404 });

  // Unknown API path: JSON 404 (not a path of the document)
  const unknown = await request("GET", urlA + "api/nothing", { headers: bearer });
  if (unknown.status !== 404 || mediaType(unknown.headers["content-type"]) !== "application/json")
    problem(`GET /api/nothing → ${unknown.status} ${unknown.headers["content-type"]}`);

  // HEAD where the document names it: the GET's headers, no body.
  for (const [label, url] of [["page", urlA], ["index.html", urlA + "index.html"],
    ["status", urlA + "api/status"], ["metrics", urlA + "metrics"], ["files", urlA + "recordings"],
    ["download", urlA + "recordings/" + enc(toKeep.file)]]) {
    const head = await check(`${label}, HEAD`, "HEAD", url, { headers: bearer, expect: 200 });
    if (head.body.length) problem(`${label}, HEAD: a body of ${head.body.length} bytes`);
  }
  await check("login, HEAD", "HEAD", urlA + "login", { expect: 200 });
  await check("download, HEAD, unknown", "HEAD", urlA + "recordings/nope.mkv", { headers: bearer, expect: 404 });
  await check("status, HEAD without token", "HEAD", urlA + "api/status", { expect: 401 });

  // A method a path does not serve: 405, Allow naming those it does, JSON.
  for (const [method, url, allow] of [
    ["GET", command("follow"), "POST"], ["DELETE", urlA + "api/cameras", "GET"],
    ["POST", urlA + "api/status", "GET, HEAD"], ["HEAD", urlA + "api/cameras", "GET"],
    ["GET", urlA + "api/config/reload", "POST"]]) {
    const answer = await request(method, url, { headers: bearer });
    const where = `${method} ${new URL(url).pathname} → ${answer.status}`;
    if (answer.status !== 405) problem(`${where}: expected 405`);
    if (answer.headers.allow !== allow) problem(`${where}: Allow is ${answer.headers.allow}, not ${allow}`);
    if (method !== "HEAD" && !validatorOf(api.components.schemas.Error)(JSON.parse(answer.body.toString() || "null")))
      problem(`${where}: not the Error schema: ${answer.body.toString().slice(0, 200)}`);
  }

  // Paths that climb out with an encoded "..", and a range past the end.
  await check("delete, climbing path", "DELETE", urlA + "api/recordings/..%2Fx",
    { headers: bearer, expect: 400, template: "/api/recordings/{file}" });
  await check("download, climbing path", "GET", urlA + "recordings/..%2F..%2Fetc%2Fpasswd",
    { headers: bearer, expect: 400, template: "/recordings/{file}" });
  await check("download, past the end", "GET", urlA + "recordings/" + enc(toKeep.file),
    { headers: { ...bearer, Range: "bytes=999999999-" }, expect: 416 });

  // B: no token set, WebRTC off
  await waitFor("recorder B's camera", async () => {
    const answer = await request("GET", urlB + "api/cameras");
    return JSON.parse(answer.body.toString()).length > 0;
  });
  const cameraB = JSON.parse((await request("GET", urlB + "api/cameras")).body.toString())[0].name;
  await check("B status, open", "GET", urlB + "api/status", { expect: 200 });
  // Without a token, nothing is shared across origins: any site could read it.
  const acrossB = await request("GET", urlB + "api/cameras",
    { headers: { Origin: "http://any-site.example" } });
  if (acrossB.headers["access-control-allow-origin"])
    problem("B, with no token, lets any origin read /api/cameras");
  await check("B follow, no token set", "POST", `${urlB}api/cameras/${enc(cameraB)}/follow?on=true`,
    { expect: 403 });
  await check("B drive, no token set", "GET", `${urlB}api/cameras/${enc(cameraB)}/drive`, { expect: 403 });
  await check("B delete, no token set", "DELETE", urlB + "api/recordings/x.mkv", { expect: 403 });
  await check("B reload, no token set", "POST", urlB + "api/config/reload", { expect: 403 });
  await check("B whep, WebRTC off", "POST", `${urlB}api/cameras/${enc(cameraB)}/whep`, {
    headers: { "Content-Type": "application/sdp" }, body: offer, expect: 404 });

  // Every operation of the document was exercised at least once.
  for (const [template, item] of Object.entries(api.paths))
    for (const method of Object.keys(item))
      if (["get", "head", "post", "delete", "put", "patch", "options"].includes(method) &&
          ![...checked].some((c) => c.startsWith(`${method.toUpperCase()} ${template} `)))
        problem(`${method.toUpperCase()} ${template} was never checked`);
} catch (error) {
  problem(error.stack || String(error));
} finally {
  stopAll();
}
if (problems.length) {
  console.error(`${problems.length} problem(s); recorder and simulator output:`);
  for (const child of children) console.error(child.output.split("\n").slice(-15).join("\n"));
  exitCode = 1;
} else {
  console.log(`docs/api/openapi.yaml: valid; ${checked.size} answers of a running recorder conform`);
}
await sleep(200);
process.exit(exitCode);

// --- helpers ----------------------------------------------------------------

// A loopback port free now, for the broker.
function freePort() {
  return new Promise((resolve) => {
    const server = net.createServer().listen(0, "127.0.0.1", () => {
      const { port } = server.address();
      server.close(() => resolve(port));
    });
  });
}

function sdpOffer() {
  const fingerprint = Array.from(crypto.randomBytes(32), (b) => b.toString(16).padStart(2, "0"))
    .join(":").toUpperCase();
  return [
    "v=0", `o=- ${Date.now()} 2 IN IP4 127.0.0.1`, "s=-", "t=0 0", "a=group:BUNDLE 0",
    "m=video 9 UDP/TLS/RTP/SAVPF 96", "c=IN IP4 0.0.0.0", "a=rtcp:9 IN IP4 0.0.0.0",
    "a=ice-ufrag:abcd", "a=ice-pwd:abcdefghijklmnopqrstuvwx", `a=fingerprint:sha-256 ${fingerprint}`,
    "a=setup:actpass", "a=mid:0", "a=recvonly", "a=rtcp-mux", "a=rtpmap:96 VP8/90000",
    "a=rtcp-fb:96 nack pli", "",
  ].join("\r\n");
}

// The drive socket by hand: a WebSocket handshake, one command (acked) and
// one malformed message (refused, neutral), each answer checked.
function driveOverWebSocket(url) {
  return new Promise((resolve) => {
    const key = crypto.randomBytes(16).toString("base64");
    const request = http.request(url, {
      agent: false,
      headers: { ...bearer, Connection: "Upgrade", Upgrade: "websocket",
                 "Sec-WebSocket-Version": "13", "Sec-WebSocket-Key": key },
    });
    const timer = setTimeout(() => {
      problem("drive WebSocket: no answers in 10 s");
      request.destroy();
      resolve();
    }, 10000);
    request.on("response", (response) => {
      problem(`drive WebSocket: ${response.statusCode} instead of 101`);
      clearTimeout(timer);
      resolve();
    });
    request.on("upgrade", (response, socket) => {
      conform("drive", "GET", url, { status: 101, headers: response.headers, body: Buffer.alloc(0) });
      const send = (text) => {
        const payload = Buffer.from(text);
        const mask = crypto.randomBytes(4);
        const masked = Buffer.from(payload.map((byte, i) => byte ^ mask[i % 4]));
        socket.write(Buffer.concat([Buffer.from([0x81, 0x80 | payload.length]), mask, masked]));
      };
      const answers = [];
      let pending = Buffer.alloc(0);
      socket.on("data", (chunk) => {
        pending = Buffer.concat([pending, chunk]);
        while (pending.length >= 2 && pending.length >= 2 + (pending[1] & 0x7f)) {
          const length = pending[1] & 0x7f;
          if ((pending[0] & 0x0f) === 1) answers.push(pending.subarray(2, 2 + length).toString());
          pending = pending.subarray(2 + length);
        }
        if (answers.length === 2) {
          clearTimeout(timer);
          const ack = api.components.schemas.DriveAck;
          const refusal = api.components.schemas.DriveError;
          const [first, second] = answers.map((text) => JSON.parse(text));
          if (!validatorOf(ack)(first) || first.ack !== 7) problem(`drive ack: ${answers[0]}`);
          if (!validatorOf(refusal)(second) || second.neutral !== true) problem(`drive refusal: ${answers[1]}`);
          checked.add("drive messages");
          socket.destroy();
          resolve();
        }
      });
      send(JSON.stringify({ seq: 7, steering: 0.1, throttle: 0 }));
      send("not json");
    });
    request.on("error", (error) => {
      problem(`drive WebSocket: ${error.message}`);
      clearTimeout(timer);
      resolve();
    });
    request.end();
  });
}
