// A Foxglove WebSocket client for wirc-recorder's tests (--foxglove): the
// server is checked with the client Foxglove itself ships
// (@foxglove/ws-protocol's FoxgloveClient over the `ws` package), and what it
// sends is decoded with schemas written by others, not with the recorder's
// own code.
//
// Interactive mode, driven by a GoogleTest through pipes:
//   node client.mjs --url ws://127.0.0.1:PORT/ [--token T] [--no-message-events]
//                   [--save-images FILE]
// (--save-images: each image's data appended to FILE as it comes, so that
// H.264 images are an elementary stream other decoders can read)
// stdout: one JSON object per line, each with "event" and "t" (Date.now() ms):
//   open, serverInfo, status, removeStatus, advertise, unadvertise, message,
//   decodeError, subscribed, unsubscribed, advertised, published, repeating,
//   stoppedRepeat, sent, paused, resumed, counts, close, error.
// stdin: one JSON command per line ({"cmd": ...}), run one after another in
//   the order given (a subscribe that waits for an advertisement holds back
//   the commands after it):
//   subscribe {topics: [...] | "all"}, unsubscribe {topics}, advertise {topic,
//   encoding, schemaName, schema?}, publish {topic, message},
//   publishText {topic, text}, repeat {topic, message, periodMs},
//   stopRepeat, sendText {text}, sendBinary {base64}, pauseReading,
//   resumeReading, counts, close, exit. EOF on stdin closes and exits.
//
// Churn mode, for many short-lived viewers at once:
//   node client.mjs churn --url U [--token T] --clients 20 --seconds 60
// prints one line {"event":"churn","connections","failed","messages","errors"}
// and exits 0, or 1 when a connection failed to open.
import { createHash } from "node:crypto";
import { appendFileSync } from "node:fs";
import { createRequire } from "node:module";
import { createInterface } from "node:readline";
import wsProtocol from "@foxglove/ws-protocol";
import protobuf from "protobufjs";
import descriptor from "protobufjs/ext/descriptor/index.js";
import WebSocket from "ws";
import { foxgloveProtobuf } from "../../support/foxglove_protobuf.mjs";

// The package is CommonJS, and Node's named-export detection misses
// FoxgloveClient (a tslib getter): take it from the default export.
const { FoxgloveClient } = wsProtocol;

// ---- output ---------------------------------------------------------------

// stdout to a pipe is synchronous in Node on Linux, so a line is out (or the
// test stopped reading) before the next thing happens, and exit loses nothing.
function emit(event, fields = {}) {
  process.stdout.write(
    JSON.stringify({ event, t: Date.now(), ...fields }, (_key, value) =>
      typeof value === "bigint" ? value.toString() : value,
    ) + "\n",
  );
}

function errorText(error) {
  return error instanceof Error ? error.message : String(error);
}

// ---- arguments ------------------------------------------------------------

function parseArguments(argv) {
  const options = { mode: "interactive", messageEvents: true, clients: 20, seconds: 60 };
  const args = [...argv];
  if (args[0] === "churn") {
    options.mode = "churn";
    args.shift();
  }
  while (args.length > 0) {
    const arg = args.shift();
    if (arg === "--url") options.url = args.shift();
    else if (arg === "--token") options.token = args.shift();
    else if (arg === "--no-message-events") options.messageEvents = false;
    else if (arg === "--save-images") options.saveImages = args.shift();
    else if (arg === "--clients") options.clients = Number(args.shift());
    else if (arg === "--seconds") options.seconds = Number(args.shift());
    else throw new Error(`unknown argument ${arg}`);
  }
  if (!options.url) throw new Error("--url is required");
  return options;
}

// FoxgloveClient leaves the subprotocol to the socket: it must be offered
// here, and `ws` then fails the handshake if the server doesn't pick it.
function connect({ url, token }) {
  const headers = token !== undefined ? { Authorization: `Bearer ${token}` } : {};
  const ws = new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL], { headers });
  return { ws, client: new FoxgloveClient({ ws }) };
}

// ---- decoding -------------------------------------------------------------

// Foxglove's protobuf definitions, as @foxglove/schemas generates them (the
// same as tests/export/mcap_check/check.mjs): a second opinion on every
// protobuf message, independent of the schema the server advertised.
let foxgloveRoot = null;
function foxgloveTypes() {
  foxgloveRoot ??= foxgloveProtobuf(
    protobuf, createRequire(import.meta.url)("@foxglove/schemas/internal"));
  return foxgloveRoot;
}

// A channel's schema as bytes: base64 for protobuf (a FileDescriptorSet),
// the text itself for JSON schema.
function schemaBytesOf(channel) {
  if (channel.schemaEncoding === "protobuf" || channel.encoding === "protobuf")
    return Buffer.from(channel.schema ?? "", "base64");
  return Buffer.from(channel.schema ?? "", "utf8");
}

// What the tests compare, in the same shape whichever definitions decoded it.
function stamp(timestamp) {
  return timestamp ? { sec: timestamp.seconds, nsec: timestamp.nanos } : null;
}
function summarize(schemaName, m) {
  switch (schemaName) {
    case "foxglove.CompressedImage":
    case "foxglove.CompressedVideo":
      return {
        format: m.format,
        frame_id: m.frame_id,
        timestamp: stamp(m.timestamp),
        dataBytes: m.data.length,
        md5: createHash("md5").update(m.data).digest("hex"),
      };
    case "foxglove.ImageAnnotations":
      return {
        points: m.points.map((p) => ({ type: p.type, count: p.points.length })),
        texts: m.texts.map((text) => text.text),
        timestamp: stamp(m.timestamp),
      };
    case "foxglove.PoseInFrame": {
      const pose = m.pose ?? {};
      const position = pose.position ?? { x: 0, y: 0, z: 0 };
      const orientation = pose.orientation ?? { x: 0, y: 0, z: 0, w: 0 };
      return {
        frame_id: m.frame_id,
        position: { x: position.x, y: position.y, z: position.z },
        orientation: { x: orientation.x, y: orientation.y, z: orientation.z, w: orientation.w },
        timestamp: stamp(m.timestamp),
      };
    }
    default:
      return null;
  }
}

const toObjectOptions = { longs: Number, enums: String, defaults: true };

// A server channel as the client keeps it: how to decode its messages.
function describeChannel(channel) {
  const kept = { ...channel, schemaBytes: schemaBytesOf(channel).length };
  if (channel.encoding !== "protobuf") return kept;
  try {
    const set = descriptor.FileDescriptorSet.decode(schemaBytesOf(channel));
    kept.advertisedType = protobuf.Root.fromDescriptor(set).lookupType(channel.schemaName);
  } catch (error) {
    kept.schemaError = `advertised schema: ${errorText(error)}`;
  }
  try {
    kept.foxgloveType = foxgloveTypes().lookupType(channel.schemaName);
  } catch (error) {
    kept.schemaError ??= `foxglove schema: ${errorText(error)}`;
  }
  return kept;
}

// Both decodes must succeed and agree; a thrown Error is the decodeError.
function decode(channel, bytes) {
  if (channel.encoding === "json") {
    return JSON.parse(new TextDecoder("utf-8", { fatal: true }).decode(bytes));
  }
  if (channel.encoding !== "protobuf") throw new Error(`unsupported encoding ${channel.encoding}`);
  if (channel.schemaError) throw new Error(channel.schemaError);
  const results = [];
  for (const [who, type] of [["advertised schema", channel.advertisedType],
                             ["foxglove schema", channel.foxgloveType]]) {
    let object;
    try {
      object = type.toObject(type.decode(bytes), toObjectOptions);
    } catch (error) {
      throw new Error(`${who}: ${errorText(error)}`);
    }
    results.push(summarize(channel.schemaName, object));
  }
  const [ours, theirs] = results.map((r) => JSON.stringify(r));
  if (ours !== theirs)
    throw new Error(`the advertised schema and Foxglove's disagree: ${ours} vs ${theirs}`);
  if (options.saveImages && channel.schemaName.startsWith("foxglove.Compressed"))
    appendFileSync(options.saveImages, channel.foxgloveType.decode(bytes).data);
  return results[0];
}

// ---- interactive mode -----------------------------------------------------

async function interactive(options) {
  const { ws, client } = connect(options);
  const channelsById = new Map(); // server channels now advertised
  const subscriptions = new Map(); // subscription id -> { channel, active }
  const clientChannels = new Map(); // topic -> our advertised channel id
  const counts = {};
  let decodeErrors = 0;
  let repeat = null; // { timer, last }
  let anyAdvertised = false;
  let advertised = () => {}; // wakes a subscribe waiting for a channel

  const opened = new Promise((resolve) => {
    client.on("open", resolve);
    client.on("close", resolve);
  });
  const closed = new Promise((resolve) => client.on("close", resolve));

  client.on("open", () => emit("open"));
  client.on("error", (error) => emit("error", { message: errorText(error) }));
  client.on("close", (event) => {
    if (repeat) clearInterval(repeat.timer);
    emit("close", { code: event.code, reason: event.reason });
    advertised(); // a subscribe waiting for channels that won't come now
  });
  client.on("serverInfo", ({ op: _op, ...info }) => emit("serverInfo", info));
  client.on("status", ({ op: _op, ...status }) => emit("status", status));
  client.on("removeStatus", ({ op: _op, ...ids }) => emit("removeStatus", ids));
  client.on("advertise", (channels) => {
    const shown = [];
    for (const channel of channels) {
      const kept = describeChannel(channel);
      channelsById.set(channel.id, kept);
      shown.push({
        id: kept.id,
        topic: kept.topic,
        encoding: kept.encoding,
        schemaName: kept.schemaName,
        schemaEncoding: kept.schemaEncoding,
        schemaBytes: kept.schemaBytes,
        ...(kept.schemaError ? { schemaError: kept.schemaError } : {}),
      });
    }
    emit("advertise", { channels: shown });
    anyAdvertised = true;
    advertised();
  });
  client.on("unadvertise", (channelIds) => {
    for (const id of channelIds) channelsById.delete(id);
    emit("unadvertise", { channelIds });
  });
  client.on("message", ({ subscriptionId, timestamp, data }) => {
    const subscription = subscriptions.get(subscriptionId);
    if (!subscription) {
      emit("error", { message: `message for unknown subscription ${subscriptionId}` });
      return;
    }
    const { channel } = subscription;
    counts[channel.topic] = (counts[channel.topic] ?? 0) + 1;
    const bytes = new Uint8Array(data.buffer, data.byteOffset, data.byteLength);
    let decoded;
    try {
      decoded = decode(channel, bytes);
    } catch (error) {
      ++decodeErrors;
      emit("decodeError", { topic: channel.topic, message: errorText(error) });
      return;
    }
    if (!options.messageEvents) return;
    emit("message", {
      topic: channel.topic,
      channelId: channel.id,
      subscriptionId,
      // Sent after its unsubscribe: the test decides whether that's late.
      ...(subscription.active ? {} : { afterUnsubscribe: true }),
      timestamp: timestamp.toString(),
      bytes: bytes.length,
      decoded,
    });
  });

  const channelOf = (topic) => [...channelsById.values()].find((c) => c.topic === topic);

  // A topic may be advertised a little after the test asks for it (a camera
  // still starting), so wait for it rather than fail at once.
  // "all" waits for the first advertisement only: the server sends it right
  // after serverInfo, so a subscribe straight after open would otherwise see
  // nothing.
  async function waitForChannels(topics, ms) {
    const deadline = Date.now() + ms;
    const missing = () =>
      topics === "all" ? !anyAdvertised : topics.some((topic) => !channelOf(topic));
    while (missing() && ws.readyState === WebSocket.OPEN && Date.now() < deadline) {
      await new Promise((resolve) => {
        const timer = setTimeout(resolve, deadline - Date.now());
        advertised = () => {
          clearTimeout(timer);
          resolve();
        };
      });
      advertised = () => {};
    }
  }

  function isOpen() {
    if (ws.readyState === WebSocket.OPEN) return true;
    emit("error", { message: "socket not open" });
    return false;
  }

  function publishBytes(topic, bytes) {
    const id = clientChannels.get(topic);
    if (id === undefined) throw new Error(`not advertised ${topic}`);
    client.sendMessage(id, bytes);
  }

  const encoder = new TextEncoder();
  const commands = {
    async subscribe({ topics }) {
      await waitForChannels(topics, 5000);
      const wanted = topics === "all" ? [...channelsById.values()].map((c) => c.topic) : topics;
      const done = [];
      for (const topic of wanted) {
        const channel = channelOf(topic);
        if (!channel) {
          emit("error", { message: `no channel ${topic}` });
          continue;
        }
        const already = [...subscriptions.values()].some(
          (s) => s.active && s.channel.id === channel.id,
        );
        if (!already && isOpen())
          subscriptions.set(client.subscribe(channel.id), { channel, active: true });
        done.push(topic);
      }
      emit("subscribed", { topics: done });
    },
    unsubscribe({ topics }) {
      const done = [];
      for (const [id, subscription] of subscriptions) {
        if (!subscription.active || !topics.includes(subscription.channel.topic)) continue;
        subscription.active = false;
        if (isOpen()) client.unsubscribe(id);
        done.push(subscription.channel.topic);
      }
      emit("unsubscribed", { topics: done });
    },
    advertise({ topic, encoding = "json", schemaName = "", schema, schemaEncoding }) {
      if (!isOpen()) return;
      const channel = { topic, encoding, schemaName };
      if (schema !== undefined) channel.schema = schema;
      if (schemaEncoding !== undefined) channel.schemaEncoding = schemaEncoding;
      const id = client.advertise(channel);
      clientChannels.set(topic, id);
      emit("advertised", { topic, id });
    },
    publish({ topic, message }) {
      if (!isOpen()) return;
      const bytes = encoder.encode(JSON.stringify(message));
      publishBytes(topic, bytes);
      emit("published", { topic, bytes: bytes.length });
    },
    publishText({ topic, text }) {
      if (!isOpen()) return;
      const bytes = encoder.encode(text);
      publishBytes(topic, bytes);
      emit("published", { topic, bytes: bytes.length });
    },
    repeat({ topic, message, periodMs = 100 }) {
      if (!clientChannels.has(topic)) throw new Error(`not advertised ${topic}`);
      if (repeat) clearInterval(repeat.timer);
      const bytes = encoder.encode(JSON.stringify(message));
      const state = { last: null };
      const send = () => {
        if (ws.readyState !== WebSocket.OPEN) return;
        publishBytes(topic, bytes);
        state.last = Date.now();
      };
      send();
      state.timer = setInterval(send, periodMs);
      repeat = state;
      emit("repeating", { topic, periodMs });
    },
    stopRepeat() {
      if (repeat) clearInterval(repeat.timer);
      emit("stoppedRepeat", { last: repeat?.last ?? null });
      repeat = null;
    },
    sendText({ text }) {
      if (!isOpen()) return;
      ws.send(text);
      emit("sent", { bytes: Buffer.byteLength(text) });
    },
    sendBinary({ base64 }) {
      if (!isOpen()) return;
      const bytes = Buffer.from(base64, "base64");
      ws.send(bytes, { binary: true });
      emit("sent", { bytes: bytes.length });
    },
    // Stops reading the TCP socket, so what the server sends piles up in its
    // own buffers: a slow viewer, as the server sees one.
    pauseReading() {
      ws.pause();
      emit("paused");
    },
    resumeReading() {
      ws.resume();
      emit("resumed");
    },
    counts() {
      emit("counts", { byTopic: counts, decodeErrors });
    },
    async close() {
      client.close();
      await Promise.race([closed, new Promise((resolve) => setTimeout(resolve, 5000))]);
    },
    exit() {
      process.exit(0);
    },
  };

  // Commands run one at a time, in order, and not before the socket opened
  // (or failed to): a test may write its first commands straight away.
  let queue = opened;
  const input = createInterface({ input: process.stdin });
  input.on("line", (line) => {
    if (!line.trim()) return;
    queue = queue.then(async () => {
      let command;
      try {
        command = JSON.parse(line);
      } catch (error) {
        emit("error", { message: `bad command: ${errorText(error)}` });
        return;
      }
      const run = commands[command.cmd];
      if (!run) {
        emit("error", { message: `unknown command ${command.cmd}` });
        return;
      }
      try {
        await run(command);
      } catch (error) {
        emit("error", { message: errorText(error) });
      }
    });
  });
  input.on("close", () => {
    queue = queue.then(async () => {
      await commands.close();
      process.exit(0);
    });
  });
}

// ---- churn mode -----------------------------------------------------------

// One viewer's visit: connect, take the advertisement, subscribe to all,
// stay a while, leave. Resolves with what happened; never rejects.
function visit(options, errors) {
  return new Promise((resolve) => {
    const { ws, client } = connect(options);
    const result = { opened: false, advertised: false, messages: 0 };
    let closing = false;
    let timer = null;
    const finish = () => {
      clearTimeout(timer);
      resolve(result);
    };
    const fail = (message) => errors.push(message);
    const leave = () => {
      closing = true;
      client.close();
      // The close handshake should be quick; don't hang on a server that
      // never answers it.
      timer = setTimeout(() => {
        fail("close handshake timed out");
        ws.terminate();
      }, 5000);
    };

    client.on("error", (error) => fail(errorText(error)));
    client.on("open", () => {
      result.opened = true;
      timer = setTimeout(() => {
        fail("no advertisement within 5 s");
        leave();
      }, 5000);
    });
    client.on("advertise", (channels) => {
      if (closing) return;
      for (const channel of channels) client.subscribe(channel.id);
      // The stay starts with the first advertisement; later ones (another
      // camera coming up) are subscribed to as well.
      if (result.advertised) return;
      result.advertised = true;
      clearTimeout(timer);
      timer = setTimeout(leave, 200 + Math.random() * 800);
    });
    client.on("message", () => ++result.messages);
    client.on("close", (event) => {
      if (result.opened && !closing) fail(`closed by the server: ${event.code} ${event.reason}`);
      finish();
    });
  });
}

async function churn(options) {
  const deadline = Date.now() + options.seconds * 1000;
  const errors = [];
  let connections = 0;
  let failed = 0;
  let messages = 0;
  const loop = async () => {
    while (Date.now() < deadline) {
      const result = await visit(options, errors);
      messages += result.messages;
      if (result.opened) {
        ++connections;
        continue;
      }
      // A server that refuses at once would make this a tight loop.
      ++failed;
      await new Promise((resolve) => setTimeout(resolve, 100));
    }
  };
  await Promise.all(Array.from({ length: options.clients }, loop));
  emit("churn", { connections, failed, messages, errors: errors.slice(0, 10) });
  process.exit(failed > 0 ? 1 : 0);
}

// ---- main -----------------------------------------------------------------

let options;
try {
  options = parseArguments(process.argv.slice(2));
} catch (error) {
  emit("error", { message: errorText(error) });
  process.exit(2);
}
if (options.mode === "churn") await churn(options);
else await interactive(options);
