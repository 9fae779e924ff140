// A ROS 2 message type's RIHS01 type hash, as rosidl_generator_type_description computes it (the
// hash Iron and later put in an endpoint's USER_DATA, "typehash=RIHS01_<hex>;"), from the
// definitions as published (@foxglove/rosmsg-msgs-common, the distro's set), never from
// caracara-ros: SHA-256 of the JSON of the type's description (its fields' names and type ids, then
// every type it references, sorted by name; no constants, no default values), written with
// Python's json.dumps separators (", ", ": "). Usage: node type_hash.mjs humble|jazzy pkg/Type
import { createHash } from "node:crypto";
import msgs from "@foxglove/rosmsg-msgs-common";

const [distro, root] = process.argv.slice(2);
const defs = msgs["ros2" + distro];
if (!defs) throw new Error(`no definitions for ${distro}`);
// type_description_interfaces/FieldType's ids; arrays add 48, bounded sequences 96, sequences 144.
const ids = { int8: 2, uint8: 3, int16: 4, uint16: 5, int32: 6, uint32: 7, int64: 8, uint64: 9, float32: 10,
  float64: 11, char: 3, bool: 15, byte: 16, string: 17, wstring: 18 };
const full = (t) => { const [pkg, name] = t.split("/"); return `${pkg}/msg/${name}`; };
// rosmsg's "time" and "duration" are builtin_interfaces' messages.
const builtin = { time: "builtin_interfaces/Time", duration: "builtin_interfaces/Duration" };
const described = new Map();
function describe(t) {
  if (described.has(full(t))) return;
  const list = t.startsWith("builtin_interfaces/")
    ? [{ name: "sec", type: "int32" }, { name: "nanosec", type: "uint32" }]
    : defs[t].definitions.filter((f) => !f.isConstant);
  const out = list.length ? list : [{ name: "structure_needs_at_least_one_member", type: "uint8" }];
  described.set(full(t), null); // its place first: the type itself leads, referenced ones follow
  described.set(full(t), { type_name: full(t), fields: out.map((f) => {
    const nested = f.isComplex ? f.type : builtin[f.type];
    if (nested) describe(nested);
    let id = nested ? 1 : ids[f.type];
    if (id === undefined) throw new Error(`${t}.${f.name}: type ${f.type}`);
    let capacity = 0;
    if (f.type === "string" && f.upperBound) id = 21;
    if (f.isArray) {
      capacity = f.arrayLength ?? f.arrayUpperBound ?? 0;
      id += f.arrayLength !== undefined ? 48 : f.arrayUpperBound ? 96 : 144;
    }
    return { name: f.name, type: { type_id: id, capacity, string_capacity: f.upperBound ?? 0,
      nested_type_name: nested ? full(nested) : "" } };
  }) });
}
describe(root);
const [top, ...refs] = [...described.values()];
refs.sort((a, b) => (a.type_name < b.type_name ? -1 : 1));
// Python's json.dumps(separators=(", ", ": ")), which rosidl hashes.
const dumps = (v) => Array.isArray(v) ? "[" + v.map(dumps).join(", ") + "]"
  : typeof v === "object" ? "{" + Object.entries(v).map(([k, x]) => JSON.stringify(k) + ": " + dumps(x)).join(", ") + "}"
  : JSON.stringify(v);
const json = dumps({ type_description: top, referenced_type_descriptions: refs });
process.stdout.write("RIHS01_" + createHash("sha256").update(json).digest("hex") + "\n");
