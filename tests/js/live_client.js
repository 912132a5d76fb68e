// A Foxglove WebSocket client (the @foxglove/ws-protocol client over `ws`) driven by JSON lines on
// stdin ({"cmd": "subscribe"|"unsubscribe", "topic": ..., "brief": true to leave the data out} or
// {"cmd": "close"}); it prints JSON lines:
// {"event": "advertise", channels}, {"event": "message", topic, log_time, msg}, {"event": "time", ns},
// {"event": "status", level, message, id}, {"event": "removeStatus", ids}, {"event": "error", ...}.
// Messages are matched to topics by their subscription id. Usage: node live_client.js ws://127.0.0.1:PORT [sdk]
"use strict";
const readline = require("readline");
const WebSocket = require("ws");
const { FoxgloveClient } = require("@foxglove/ws-protocol");
const { makeDecoder, toJson } = require("./decode");

const out = (obj) => process.stdout.write(toJson(obj) + "\n");
// The client at its defaults, as ws-protocol's README writes it: the socket offers
// FoxgloveClient.SUPPORTED_SUBPROTOCOL ("foxglove.websocket.v1"). A second argument "sdk" offers
// "foxglove.sdk.v1" instead (what foxglove-sdk's own server names the same protocol).
const protocol = process.argv[3] === "sdk" ? "foxglove.sdk.v1" : FoxgloveClient.SUPPORTED_SUBPROTOCOL;
const ws = new WebSocket(process.argv[2], [protocol]);
const client = new FoxgloveClient({ ws });
const byTopic = new Map();   // topic -> {channel, decode}
const bySub = new Map();     // subscription id -> topic
const subOf = new Map();     // topic -> subscription id
const brief = new Set();     // topics whose messages are reported without their data (large clouds)

client.on("open", () => out({ event: "open", protocol: ws.protocol }));
client.on("status", (s) => out({ event: "status", level: s.level, message: s.message, id: s.id }));
client.on("removeStatus", (s) => out({ event: "removeStatus", ids: s.statusIds }));
client.on("serverInfo", (info) => out({ event: "serverInfo", name: info.name, capabilities: info.capabilities }));
client.on("error", (err) => out({ event: "error", message: String(err && err.message ? err.message : err) }));
client.on("close", () => { out({ event: "closed" }); process.exit(0); });
client.on("advertise", (channels) => {
  for (const ch of channels) {
    // binary schema encodings (protobuf) come base64 encoded, text ones (ros2msg) as text
    const bytes = ch.schemaEncoding === "protobuf" ? Buffer.from(ch.schema, "base64") : Buffer.from(ch.schema, "utf8");
    let decode = null, problem = null;
    try { decode = makeDecoder(ch.encoding, ch.schemaName, ch.schemaEncoding, bytes); } catch (e) { problem = String(e.message); }
    byTopic.set(ch.topic, { channel: ch, decode });
    if (problem) out({ event: "error", topic: ch.topic, message: problem });
  }
  out({ event: "advertise", channels: channels.map((c) => ({ id: c.id, topic: c.topic, encoding: c.encoding,
    schemaName: c.schemaName, schemaEncoding: c.schemaEncoding })) });
});
client.on("time", ({ timestamp }) => out({ event: "time", ns: Number(timestamp) }));
client.on("message", ({ subscriptionId, timestamp, data }) => {
  const topic = bySub.get(subscriptionId);
  const entry = byTopic.get(topic);
  try {
    const bytes = new Uint8Array(data.buffer, data.byteOffset, data.byteLength);
    if (brief.has(topic)) {
      const msg = entry.decode(bytes);
      out({ event: "message", topic, log_time: Number(timestamp), size: bytes.length,
        msg: { width: msg.width, height: msg.height, frame_id: msg.header && msg.header.frame_id } });
      return;
    }
    out({ event: "message", topic, log_time: Number(timestamp), size: bytes.length, msg: entry.decode(bytes),
      raw: Buffer.from(bytes).toString("base64") });
  } catch (e) {
    out({ event: "error", topic, message: `decode failed: ${e.message}` });
  }
});

readline.createInterface({ input: process.stdin }).on("line", (line) => {
  const cmd = JSON.parse(line);
  if (cmd.cmd === "subscribe") {
    const entry = byTopic.get(cmd.topic);
    if (!entry) { out({ event: "error", topic: cmd.topic, message: "no such channel" }); return; }
    if (cmd.brief) brief.add(cmd.topic);
    const id = client.subscribe(entry.channel.id);
    bySub.set(id, cmd.topic);
    subOf.set(cmd.topic, id);
    out({ event: "subscribed", topic: cmd.topic });
  } else if (cmd.cmd === "unsubscribe") {
    const id = subOf.get(cmd.topic);
    if (id !== undefined) { client.unsubscribe(id); subOf.delete(cmd.topic); }
    out({ event: "unsubscribed", topic: cmd.topic });
  } else if (cmd.cmd === "close") {
    client.close();
  }
});
