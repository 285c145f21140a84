// Independent check of a bioflex-jsb MCAP log with the @mcap/core indexed reader (Node).
// Usage: node check_mcap.cjs FILE.mcap   (run where @mcap/core, @foxglove/wasm-zstd and
// protobufjs are installed). Prints one JSON object: message counts per topic (read back
// through the chunk indexes, every chunk's CRC checked), the statistics record's counts,
// whether the summary CRC (checked by Initialize) and the data-section CRC (checked here)
// hold, and one decoded message per topic: protobuf messages are decoded with protobufjs
// from the file's own FileDescriptorSet schemas (as Foxglove does), JSON ones (older logs)
// with JSON.parse.
"use strict";
const fs = require("fs");
const { McapIndexedReader } = require("@mcap/core");
const { crc32 } = require("@foxglove/crc");
const zstd = require("@foxglove/wasm-zstd");
const protobuf = require("protobufjs");
const descriptor = require("protobufjs/ext/descriptor");

const decoders = new Map(); // channel id -> function(bytes) -> object
function decoderFor(reader, channel) {
  let d = decoders.get(channel.id);
  if (d) return d;
  if (channel.messageEncoding === "json") {
    d = (data) => JSON.parse(new TextDecoder().decode(data));
  } else if (channel.messageEncoding === "protobuf") {
    const schema = reader.schemasById.get(channel.schemaId);
    if (!schema || schema.encoding !== "protobuf") throw new Error(`no protobuf schema: ${channel.topic}`);
    const root = protobuf.Root.fromDescriptor(descriptor.FileDescriptorSet.decode(schema.data));
    const type = root.lookupType(schema.name);
    d = (data) => type.toObject(type.decode(data), { longs: Number, defaults: false });
  } else {
    throw new Error(`unexpected message encoding ${channel.messageEncoding} on ${channel.topic}`);
  }
  decoders.set(channel.id, d);
  return d;
}

async function main(path) {
  await zstd.isLoaded;
  const fd = fs.openSync(path, "r");
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
    decompressHandlers: { zstd: (data, n) => zstd.decompress(data, Number(n)) },
  });
  const counts = {};
  let last = -1n;
  let ordered = true;
  const samples = {};
  const encodings = {};
  for await (const msg of reader.readMessages({ validateCrcs: true })) {
    const channel = reader.channelsById.get(msg.channelId);
    const topic = channel.topic;
    counts[topic] = (counts[topic] || 0) + 1;
    const decoded = decoderFor(reader, channel)(msg.data); // every message decodes
    encodings[topic] = channel.messageEncoding;
    if (counts[topic] === 2) samples[topic] = decoded;
    if (msg.logTime < last) ordered = false;
    last = msg.logTime;
  }
  const statistics = {};
  for (const [id, n] of reader.statistics.channelMessageCounts) {
    statistics[reader.channelsById.get(id).topic] = Number(n);
  }
  // data-section CRC: every byte from the start up to the Data End record (13 bytes before
  // the summary section)
  let dataCrcOk = null;
  if (reader.dataSectionCrc !== undefined && reader.footer.summaryStart > 0n) {
    const end = Number(reader.footer.summaryStart) - 13;
    const buf = Buffer.alloc(end);
    fs.readSync(fd, buf, 0, end, 0);
    dataCrcOk = crc32(buf) === reader.dataSectionCrc;
  }
  fs.closeSync(fd);
  const schemas = {};
  for (const ch of reader.channelsById.values()) {
    schemas[ch.topic] = reader.schemasById.get(ch.schemaId).name;
  }
  console.log(JSON.stringify({
    counts, statistics, schemas, encodings, samples, ordered, dataCrcOk,
    chunks: reader.chunkIndexes.length, library: reader.header.library,
  }));
}

main(process.argv[2]).catch((err) => {
  console.error(String(err && err.message ? err.message : err));
  process.exit(1);
});
