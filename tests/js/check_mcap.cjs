// Independent check of a bioflex-jsb MCAP log with the @mcap/core indexed reader (Node).
// Usage: node check_mcap.cjs FILE.mcap   (run where @mcap/core and @foxglove/wasm-zstd are
// installed). Prints one JSON object: message counts per topic (read back through the chunk
// indexes, every chunk's CRC checked), the statistics record's counts, and whether the
// summary CRC (checked by Initialize) and the data-section CRC (checked here) hold.
"use strict";
const fs = require("fs");
const { McapIndexedReader } = require("@mcap/core");
const { crc32 } = require("@foxglove/crc");
const zstd = require("@foxglove/wasm-zstd");

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
  for await (const msg of reader.readMessages({ validateCrcs: true })) {
    const topic = reader.channelsById.get(msg.channelId).topic;
    counts[topic] = (counts[topic] || 0) + 1;
    JSON.parse(new TextDecoder().decode(msg.data)); // every message is JSON
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
    counts, statistics, schemas, ordered, dataCrcOk,
    chunks: reader.chunkIndexes.length, library: reader.header.library,
  }));
}

main(process.argv[2]).catch((err) => {
  console.error(String(err && err.message ? err.message : err));
  process.exit(1);
});
