// Decoders for the Foxglove-facing data of Sensorium, written only with independent packages:
// ROS 2 CDR via @foxglove/rosmsg + @foxglove/rosmsg2-serialization, protobuf via protobufjs.
"use strict";
const { parse } = require("@foxglove/rosmsg");
const { MessageReader } = require("@foxglove/rosmsg2-serialization");
const protobuf = require("protobufjs");
const descriptor = require("protobufjs/ext/descriptor");

// A decoder for one channel: (messageEncoding, schemaName, schemaEncoding, schema bytes) -> fn(bytes) -> object.
function makeDecoder(messageEncoding, schemaName, schemaEncoding, schemaBytes) {
  if (messageEncoding === "cdr" && schemaEncoding === "ros2msg") {
    const defs = parse(Buffer.from(schemaBytes).toString("utf8"), { ros2: true });
    const reader = new MessageReader(defs);
    return (data) => reader.readMessage(data);
  }
  if (messageEncoding === "protobuf" && schemaEncoding === "protobuf") {
    const set = descriptor.FileDescriptorSet.decode(Buffer.from(schemaBytes));
    const root = protobuf.Root.fromDescriptor(set);
    const type = root.lookupType(schemaName);
    return (data) => type.toObject(type.decode(data), { longs: Number, defaults: true, bytes: Array });
  }
  throw new Error(`unsupported channel: message encoding ${messageEncoding}, schema ${schemaName} (${schemaEncoding})`);
}

// JSON.stringify replacer: typed arrays as plain arrays, bigints as numbers, non-finite numbers as
// markers that toJson turns into the Infinity/NaN tokens Python's json module reads.
function replacer(_key, value) {
  if (typeof value === "bigint") return Number(value);
  if (ArrayBuffer.isView(value) && !(value instanceof DataView)) return Array.from(value, (v) => replacer("", v));
  if (typeof value === "number" && !Number.isFinite(value)) return `@@${value}@@`;
  return value;
}

function toJson(obj) {
  return JSON.stringify(obj, replacer).replace(/"@@(-?Infinity|NaN)@@"/g, "$1");
}

module.exports = { makeDecoder, replacer, toJson };
