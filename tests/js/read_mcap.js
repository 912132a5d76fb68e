// Validate and decode a Sensorium recording with Foxglove's own TypeScript MCAP reader (@mcap/core)
// and the independent decoders of decode.js. Prints one JSON object:
//   {profile, channels: [{topic, schemaName, schemaEncoding, messageEncoding, count}], errors: [...],
//    last: {topic: last decoded message}, messages, every: [{topic, log_time, msg}]}
// Every chunk CRC is checked; every message of every channel is decoded. ``every`` lists the
// messages of the TOPICs named after the file, each decoded, in the order the reader gives them.
// Usage: node read_mcap.js FILE.mcap [TOPIC...]
"use strict";
const fs = require("fs");
const { McapIndexedReader } = require("@mcap/core");
const { decompress } = require("fzstd");
const { makeDecoder, toJson } = require("./decode");

async function main() {
  const fd = fs.openSync(process.argv[2], "r");
  const size = BigInt(fs.fstatSync(fd).size);
  const readable = {
    size: async () => size,
    read: async (offset, length) => {
      const buf = Buffer.alloc(Number(length));
      fs.readSync(fd, buf, 0, Number(length), Number(offset));
      return new Uint8Array(buf.buffer, buf.byteOffset, buf.byteLength);
    },
  };
  const reader = await McapIndexedReader.Initialize({
    readable,
    decompressHandlers: { zstd: (data, n) => { const out = decompress(data); if (BigInt(out.length) !== n) throw new Error("zstd size"); return out; } },
  });
  const errors = [];
  const decoders = new Map();
  const channels = new Map();
  for (const [id, ch] of reader.channelsById) {
    const schema = reader.schemasById.get(ch.schemaId);
    const info = { topic: ch.topic, schemaName: schema ? schema.name : "", schemaEncoding: schema ? schema.encoding : "",
      messageEncoding: ch.messageEncoding, count: 0 };
    channels.set(id, info);
    try {
      if (!schema) throw new Error("no schema");
      decoders.set(id, makeDecoder(ch.messageEncoding, schema.name, schema.encoding, schema.data));
    } catch (e) {
      errors.push({ topic: ch.topic, error: String(e.message) });
    }
  }
  const last = {};
  const listed = new Set(process.argv.slice(3));
  const every = [];
  let messages = 0;
  for await (const msg of reader.readMessages({ validateCrcs: true })) {
    const info = channels.get(msg.channelId);
    const decode = decoders.get(msg.channelId);
    info.count += 1;
    messages += 1;
    if (!decode) continue;
    try {
      const value = decode(msg.data);
      last[info.topic] = { log_time: Number(msg.logTime), sequence: msg.sequence, msg: value };
      if (listed.has(info.topic)) every.push({ topic: info.topic, log_time: Number(msg.logTime), msg: value });
    } catch (e) {
      if (errors.length < 50) errors.push({ topic: info.topic, log_time: Number(msg.logTime), error: `decode failed: ${e.message}` });
    }
  }
  process.stdout.write(toJson({ profile: reader.header.profile, channels: [...channels.values()], errors, last, messages, every }) + "\n");
}

main().catch((e) => { process.stderr.write(String(e.stack || e) + "\n"); process.exit(1); });
