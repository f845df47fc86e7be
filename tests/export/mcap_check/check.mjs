// Reads an MCAP file with readers written by others and prints what it
// found, as JSON, for the export tests to compare with the recordings:
//   node check.mjs FILE.mcap [--images-to FILE]
// (--images-to: every image's data, one after the other, into FILE: an
// H.264 export's images are then an elementary stream other decoders read)
// - @mcap/core's McapIndexedReader (chunk indexes, summary, CRCs) and
//   McapStreamReader (every record in order, the data section's CRC);
// - every JSON message validated against Foxglove's own JSON schema for its
//   type (@foxglove/schemas), with ajv; every protobuf message decoded
//   with Foxglove's own protobuf definitions (@foxglove/schemas' generated
//   .proto, parsed by protobufjs), and the file's Schema record read as the
//   FileDescriptorSet the MCAP spec asks for;
// - a read from the middle (startTime), which the chunk index serves.
import { readFile, writeFile } from "node:fs/promises";
import { createHash } from "node:crypto";
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import * as foxglove from "@foxglove/schemas/jsonschema.js";
import Ajv from "ajv";
import { decompress } from "fzstd";
import protobuf from "protobufjs";
import descriptor from "protobufjs/ext/descriptor/index.js";
import { createRequire } from "node:module";
import { foxgloveProtobuf } from "../../support/foxglove_protobuf.mjs";

// Foxglove's protobuf definitions, as their package generates them.
const foxgloveTypes = foxgloveProtobuf(
  protobuf, createRequire(import.meta.url)("@foxglove/schemas/internal"));

const bytes = new Uint8Array(await readFile(process.argv[2]));
const imagesTo = process.argv[3] === "--images-to" ? process.argv[4] : null;
const imageData = [];
const decompressHandlers = { zstd: (data) => decompress(data) };
const readable = {
  size: async () => BigInt(bytes.length),
  read: async (offset, size) => bytes.subarray(Number(offset), Number(offset + size)),
};
const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers });

const ajv = new Ajv({ strict: false });
const foxgloveSchemas = {
  "foxglove.CompressedImage": foxglove.CompressedImage,
  "foxglove.CompressedVideo": foxglove.CompressedVideo,
  "foxglove.ImageAnnotations": foxglove.ImageAnnotations,
  "foxglove.Log": foxglove.Log,
};
const validators = new Map();
const descriptorProblems = [];
for (const [id, channel] of reader.channelsById) {
  const schema = reader.schemasById.get(channel.schemaId);
  if (channel.messageEncoding === "protobuf") {
    // The file's own schema: a FileDescriptorSet that holds the type.
    try {
      const set = descriptor.FileDescriptorSet.decode(schema.data);
      protobuf.Root.fromDescriptor(set).lookupType(schema.name);
    } catch (error) {
      descriptorProblems.push({ topic: channel.topic, error: String(error) });
    }
    validators.set(id, {
      topic: channel.topic,
      name: schema.name,
      encoding: "protobuf",
      type: foxgloveTypes.lookupType(schema.name),
    });
    continue;
  }
  const ours = JSON.parse(new TextDecoder().decode(schema.data));
  validators.set(id, {
    topic: channel.topic,
    name: schema.name,
    encoding: channel.messageEncoding,
    ours: ajv.compile(ours),
    theirs: foxgloveSchemas[schema.name] ? ajv.compile(foxgloveSchemas[schema.name]) : null,
  });
}

const result = {
  topics: {},
  images: [],
  invalid: [],
  chunks: reader.chunkIndexes.length,
  linesTimed: 0,
  linesOffTheirUtc: [],
  logsOffTheirTimestamp: 0,
  encodings: {},
  outlines: 0,
  annotationsOffTheirTime: 0,
};
result.compression = [...new Set(reader.chunkIndexes.map((c) => c.compression))];
result.statistics = reader.statistics
  ? { messages: Number(reader.statistics.messageCount), chunks: reader.statistics.chunkCount }
  : null;
let last = -1n;
result.ordered = true;
for await (const message of reader.readMessages()) {
  const v = validators.get(message.channelId);
  result.topics[v.topic] = (result.topics[v.topic] ?? 0) + 1;
  if (message.logTime < last) result.ordered = false;
  last = message.logTime;
  let json;
  if (v.type) {
    try {
      json = v.type.toObject(v.type.decode(message.data), { longs: Number, defaults: true });
    } catch (error) {
      if (result.invalid.length < 5)
        result.invalid.push({ topic: v.topic, who: "foxglove protobuf", errors: String(error) });
      continue;
    }
    const problem = v.type.verify(json);
    if (problem && result.invalid.length < 5)
      result.invalid.push({ topic: v.topic, who: "foxglove protobuf", errors: problem });
    result.encodings[v.topic] = "protobuf";
  } else {
    json = JSON.parse(new TextDecoder().decode(message.data));
    for (const [who, check] of [["ours", v.ours], ["foxglove", v.theirs]]) {
      if (check && !check(json) && result.invalid.length < 5)
        result.invalid.push({ topic: v.topic, who, errors: check.errors });
    }
    result.encodings[v.topic] = "json";
  }
  if (v.name === "foxglove.ImageAnnotations") {
    result.outlines += json.points.length;
    const stamp = BigInt(json.timestamp.seconds) * 1000000000n + BigInt(json.timestamp.nanos);
    if (stamp !== message.logTime) result.annotationsOffTheirTime += 1;
  }
  // A telemetry line's log_time is its own utc (ms); a Log's timestamp is
  // its log_time.
  if (v.name === "wircam.Telemetry" && typeof json.utc === "string") {
    result.linesTimed += 1;
    const utcNs = BigInt(Date.parse(json.utc)) * 1000000n;
    if (utcNs !== message.logTime && result.linesOffTheirUtc.length < 5)
      result.linesOffTheirUtc.push({ utc: json.utc, logTime: message.logTime.toString() });
  }
  if (v.name === "foxglove.Log") {
    const stamp = BigInt(json.timestamp.sec) * 1000000000n + BigInt(json.timestamp.nsec);
    if (stamp !== message.logTime) result.logsOffTheirTimestamp += 1;
  }
  if (v.name === "foxglove.CompressedImage" || v.name === "foxglove.CompressedVideo") {
    const data = Buffer.from(json.data);
    imageData.push(data);
    result.images.push({
      logTime: message.logTime.toString(),
      md5: createHash("md5").update(data).digest("hex"),
      format: json.format,
    });
  }
}

// Seeking: from the middle of the images, the reader starts there.
if (result.images.length > 2) {
  const middle = BigInt(result.images[Math.floor(result.images.length / 2)].logTime);
  let first = null;
  let count = 0;
  for await (const message of reader.readMessages({ startTime: middle })) {
    if (first === null) first = message.logTime;
    ++count;
  }
  result.seek = { from: middle.toString(), first: first?.toString(), messages: count };
}

// Straight through, every record, with the CRCs checked.
const stream = new McapStreamReader({ validateCrcs: true, decompressHandlers });
stream.append(bytes);
let records = 0;
try {
  for (let record; (record = stream.nextRecord()); ) ++records;
  result.streamRecords = records;
  result.streamDone = stream.done();
} catch (error) {
  result.streamError = String(error);
}
if (descriptorProblems.length) result.invalid.push(...descriptorProblems);
if (imagesTo) await writeFile(imagesTo, Buffer.concat(imageData));
console.log(JSON.stringify(result));
