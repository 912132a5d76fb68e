// Many Foxglove viewers in turn (the @foxglove/ws-protocol client with its own subprotocol,
// FoxgloveClient.SUPPORTED_SUBPROTOCOL): each connects, subscribes to every channel, waits for
// `perViewer` messages (or --wait seconds, 5 by default, counted from its last subscribe), then
// vanishes without unsubscribing (the socket is destroyed), or with --churn N subscribes and
// unsubscribes every channel N times first. Prints one JSON line: {viewers, messages, failed,
// churned, first_ms} (first_ms: the longest wait from a viewer's last subscribe to its first
// message). Usage: node viewer_churn.js ws://127.0.0.1:PORT VIEWERS [PER_VIEWER] [--parallel K]
// [--churn N] [--wait S]
"use strict";
const WebSocket = require("ws");
const { FoxgloveClient } = require("@foxglove/ws-protocol");

const url = process.argv[2];
const viewers = Number(process.argv[3] || 10);
const perViewer = Number(process.argv[4] || 5);
const opt = (name, dflt) => { const i = process.argv.indexOf(name); return i > 0 ? Number(process.argv[i + 1]) : dflt; };
const parallel = opt("--parallel", 10);
const churn = opt("--churn", 0);
const waitMs = opt("--wait", 5) * 1000;
let messages = 0, failed = 0, churned = 0, done = 0, started = 0, firstMs = 0;
const reasons = [];                         // why a viewer failed (the first few)

function one() {
  return new Promise((resolve) => {
    const ws = new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
    const client = new FoxgloveClient({ ws });
    let got = 0, finished = false, timer = null, subscribedAt = 0;
    const arm = () => { clearTimeout(timer); timer = setTimeout(() => finish(got > 0, subscribedAt ? "no message in time" : "no advertise in time"), waitMs); };
    const finish = (ok, why) => {
      if (finished) return;
      finished = true;
      if (!ok) { failed += 1; if (reasons.length < 5) reasons.push(why); }
      clearTimeout(timer);
      ws.terminate();                        // vanish: no unsubscribe, no close handshake
      resolve();
    };
    arm();                                   // until the channels are advertised
    client.on("error", (err) => finish(false, `error: ${err && err.message ? err.message : err}`));
    ws.on("close", (code) => finish(got > 0, `closed by the server (${code})`));
    client.on("advertise", (channels) => {
      for (let i = 0; i < churn; i++) {
        const ids = channels.map((c) => client.subscribe(c.id));
        for (const id of ids) client.unsubscribe(id);
        churned += ids.length;
      }
      for (const c of channels) client.subscribe(c.id);
      subscribedAt = Date.now();
      arm();                                 // the wait runs from the last subscribe
    });
    client.on("message", () => {
      if (got === 0 && subscribedAt) firstMs = Math.max(firstMs, Date.now() - subscribedAt);
      messages += 1; got += 1; if (got >= perViewer) finish(true, "");
    });
  });
}

async function worker() {
  while (started < viewers) { started += 1; await one(); done += 1; }
}
Promise.all(Array.from({ length: Math.min(parallel, viewers) }, worker)).then(() => {
  process.stdout.write(JSON.stringify({ viewers: done, messages, failed, churned, first_ms: firstMs, reasons }) + "\n");
  process.exit(0);
});
