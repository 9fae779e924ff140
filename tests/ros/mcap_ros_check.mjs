// A dive exported with caracaractl export --format mcap --encoding cdr, read as rosbag2 would:
// the reference MCAP reader (@mcap/core, indexed, CRCs checked), every schema a ros2msg parsed by
// @foxglove/rosmsg, every message decoded by @foxglove/rosmsg2-serialization from its channel's
// schema alone and written back to the same bytes. Prints {"profile","topics":{topic:{type,count}},"messages":{topic:[decoded...]}}
// (each topic's messages in order), each topic's channel metadata ("metadata": rosbag2's
// offered_qos_profiles) and the file's Metadata records ("records": [{name, metadata}], read
// through the summary's Metadata Index as rosbag2 reads its "rosbag2" record), for test_ros.py to
// judge against the dive. Usage: node
// mcap_ros_check.mjs FILE
import { readFileSync } from "node:fs";
import { McapIndexedReader } from "@mcap/core";
import { parse } from "@foxglove/rosmsg";
import { MessageReader, MessageWriter } from "@foxglove/rosmsg2-serialization";

const bytes = new Uint8Array(readFileSync(process.argv[2]));
const readable = {
  size: async () => BigInt(bytes.length),
  read: async (offset, size) => bytes.slice(Number(offset), Number(offset + size)),
};
const reader = await McapIndexedReader.Initialize({ readable });
const decoder = new TextDecoder();
const readers = new Map();
const out = { profile: reader.header.profile, topics: {}, messages: {}, records: [] };
for (const [id, ch] of reader.channelsById) {
  const schema = reader.schemasById.get(ch.schemaId);
  if (schema.encoding !== "ros2msg" || ch.messageEncoding !== "cdr")
    throw new Error(`${ch.topic}: ${schema.encoding}/${ch.messageEncoding}, not ros2msg/cdr`);
  const defs = parse(decoder.decode(schema.data), { ros2: true });
  readers.set(id, { reader: new MessageReader(defs), writer: new MessageWriter(defs) });
  out.topics[ch.topic] = { type: schema.name, count: 0, metadata: Object.fromEntries(ch.metadata) };
  out.messages[ch.topic] = [];
}
for await (const m of reader.readMetadata())
  out.records.push({ name: m.name, metadata: Object.fromEntries(m.metadata) });
if (reader.metadataIndexes.length !== out.records.length) throw new Error("a Metadata record without its index");
let last = 0n;
for await (const m of reader.readMessages({ validateCrcs: true })) {
  const ch = reader.channelsById.get(m.channelId);
  if (m.logTime < last) throw new Error("log times go back");
  last = m.logTime;
  const { reader: r, writer: w } = readers.get(m.channelId);
  const msg = r.readMessage(m.data);
  // The reference serializer gives back the very bytes the exporter wrote.
  if (Buffer.compare(Buffer.from(w.writeMessage(msg)), Buffer.from(m.data)) !== 0)
    throw new Error(`${ch.topic}: the bytes differ from rosmsg2-serialization's`);
  out.topics[ch.topic].count++;
  out.messages[ch.topic].push(msg);
}
process.stdout.write(JSON.stringify(out, (k, v) => (ArrayBuffer.isView(v) ? Array.from(v) : typeof v === "bigint" ? Number(v) : v)));
