// A dive exported with caracaractl export --format mcap, judged by the reference MCAP reader
// (@mcap/core): the indexed reader (summary CRC, chunk index, message indexes, statistics) and
// the stream reader (every record, chunk CRCs), the data section's CRC checked here. Every
// message decodes against its channel's JSON Schema, times never go back, and the counts equal
// the dive's (CARACARA_SAMPLES samples on each channel but /events, CARACARA_EVENTS there).
// Run by test_bridge.py.
import { test } from "node:test";
import assert from "node:assert/strict";
import { readFileSync } from "node:fs";
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import { crc32 } from "@foxglove/crc";
import Ajv2020 from "ajv/dist/2020.js";

const bytes = new Uint8Array(readFileSync(process.env.CARACARA_MCAP));
const samples = Number(process.env.CARACARA_SAMPLES);
const events = Number(process.env.CARACARA_EVENTS);
const decoder = new TextDecoder();

test("the indexed reader: summary, statistics and every message through the index", async () => {
  const readable = {
    size: async () => BigInt(bytes.length),
    read: async (offset, size) => bytes.slice(Number(offset), Number(offset + size)),
  };
  const reader = await McapIndexedReader.Initialize({ readable });
  assert.equal(reader.statistics.messageCount, BigInt(samples * 13 + events));
  assert.equal(reader.channelsById.size, 14);
  assert.ok(reader.chunkIndexes.length >= 1);
  const ajv = new Ajv2020({ strict: false });
  const validators = new Map();
  for (const [id, ch] of reader.channelsById) {
    const schema = reader.schemasById.get(ch.schemaId);
    assert.equal(schema.encoding, "jsonschema");
    assert.equal(ch.messageEncoding, "json");
    validators.set(id, ajv.compile(JSON.parse(decoder.decode(schema.data))));
  }
  const counts = new Map();
  let last = 0n;
  for await (const m of reader.readMessages({ validateCrcs: true })) {
    const ch = reader.channelsById.get(m.channelId);
    const validate = validators.get(m.channelId);
    const msg = JSON.parse(decoder.decode(m.data));
    assert.ok(validate(msg), `${ch.topic}: ${ajv.errorsText(validate.errors)}`);
    assert.ok(m.logTime >= last, "log times go back");
    last = m.logTime;
    counts.set(ch.topic, (counts.get(ch.topic) ?? 0) + 1);
  }
  for (const ch of reader.channelsById.values())
    assert.equal(counts.get(ch.topic) ?? 0, ch.topic === "/events" ? events : samples, ch.topic);
  for (const [id, n] of reader.statistics.channelMessageCounts)
    assert.equal(Number(n), counts.get(reader.channelsById.get(id).topic) ?? 0);
});

test("the stream reader: every record, chunk CRCs, and the data section's CRC", () => {
  const reader = new McapStreamReader({ validateCrcs: true });
  reader.append(bytes);
  let messages = 0;
  let dataEnd = null;
  let offset = 8; // after the magic: the record lengths give each record's place
  let dataEndOffset = -1;
  for (let r; (r = reader.nextRecord()); ) {
    if (r.type === "Message") messages++;
    if (r.type === "DataEnd") dataEnd = r;
  }
  assert.ok(reader.done(), "the reader reached the footer and the closing magic");
  // Walk the top-level records to find where Data End starts.
  const view = new DataView(bytes.buffer);
  while (offset < bytes.length - 8) {
    const op = bytes[offset];
    const len = Number(view.getBigUint64(offset + 1, true));
    if (op === 0x0f) { dataEndOffset = offset; break; }
    offset += 9 + len;
  }
  assert.equal(messages, samples * 13 + events);
  assert.ok(dataEnd && dataEndOffset > 0);
  assert.equal(dataEnd.dataSectionCrc, crc32(bytes.subarray(0, dataEndOffset)));
});
