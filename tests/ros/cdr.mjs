// The reference CDR codec for the tests: @foxglove/rosmsg2-serialization with the ROS 2 message
// definitions of @foxglove/rosmsg-msgs-common and rmw_dds_common's (rmw_dds_common.mjs). One
// request a line on stdin, one answer a line:
//   {"op":"encode","distro":"humble","type":"sensor_msgs/Range","msg":{...}} -> {"hex":"..."}
//   {"op":"decode","distro":"humble","type":"sensor_msgs/Range","hex":"..."} -> {"msg":{...}}
// (NaN and typed arrays are carried as JSON-able values: NaN as the string "NaN".)
import msgs from "@foxglove/rosmsg-msgs-common";
import { MessageReader, MessageWriter } from "@foxglove/rosmsg2-serialization";
import readline from "node:readline";
import { withRmwDdsCommon } from "./rmw_dds_common.mjs";

const cache = new Map();
function codec(distro, type) {
  const key = distro + " " + type;
  if (!cache.has(key)) {
    const defs = withRmwDdsCommon(distro, msgs["ros2" + distro]);
    if (!defs[type]) throw new Error(`no ${type} in ros2${distro}`);
    const all = [defs[type], ...Object.values(defs).filter((d) => d.name !== type)];
    cache.set(key, { reader: new MessageReader(all), writer: new MessageWriter(all) });
  }
  return cache.get(key);
}
const revive = (k, v) => (v === "NaN" ? NaN : v);
const plain = (k, v) => (ArrayBuffer.isView(v) ? Array.from(v) : typeof v === "bigint" ? Number(v)
  : typeof v === "number" && Number.isNaN(v) ? "NaN" : v);
const rl = readline.createInterface({ input: process.stdin });
for await (const line of rl) {
  if (!line.trim()) continue;
  const req = JSON.parse(line, revive);
  const c = codec(req.distro, req.type);
  let res;
  if (req.op === "encode") res = { hex: Buffer.from(c.writer.writeMessage(req.msg)).toString("hex") };
  else res = { msg: c.reader.readMessage(Buffer.from(req.hex, "hex")) };
  process.stdout.write(JSON.stringify(res, plain) + "\n");
}
