// The Fast DDS peer's types: the ROS 2 message definitions as published
// (@foxglove/rosmsg-msgs-common, DISTRO's set) turned into DDS IDL the way rosidl maps them
// (module pkg::msg::dds_, struct Type_, an empty message's one uint8), for fastddsgen, with
// rmw_dds_common's graph messages (rmw_dds_common.mjs). Never from the project's own IDL.
// Usage: node msg_to_idl.mjs humble|jazzy TYPE... > ros.idl
import msgs from "@foxglove/rosmsg-msgs-common";
import { withRmwDdsCommon } from "./rmw_dds_common.mjs";

const [distro, ...roots] = process.argv.slice(2);
const defs = withRmwDdsCommon(distro, msgs["ros2" + distro]);
const prim = { bool: "boolean", byte: "octet", char: "uint8", int8: "int8", uint8: "uint8", int16: "int16",
  uint16: "uint16", int32: "int32", uint32: "uint32", int64: "int64", uint64: "uint64", float32: "float",
  float64: "double", string: "string" };
const ddsName = (t) => { const [pkg, name] = t.split("/"); return `${pkg}::msg::dds_::${name}_`; };
const order = [];
const seen = new Set();
function visit(t) {
  if (seen.has(t)) return;
  seen.add(t);
  const d = defs[t];
  if (!d) throw new Error(`no definition of ${t} in ros2${distro}`);
  for (const f of d.definitions) if (f.isComplex && !f.isConstant) visit(f.type);
  order.push(t);
}
roots.forEach(visit);
// rosmsg's "time" and "duration" are builtin_interfaces/Time and Duration (int32 sec, uint32 nanosec).
let out = "module builtin_interfaces { module msg { module dds_ {\n  @final struct Time_ { int32 sec; uint32 nanosec; };\n" +
  "  @final struct Duration_ { int32 sec; uint32 nanosec; };\n}; }; };\n";
prim.time = "builtin_interfaces::msg::dds_::Time_";
prim.duration = "builtin_interfaces::msg::dds_::Duration_";
for (const t of order) {
  const [pkg, name] = t.split("/");
  const fields = defs[t].definitions.filter((f) => !f.isConstant);
  const body = fields.length === 0 ? ["uint8 structure_needs_at_least_one_member;"] : fields.map((f) => {
    const type = f.isComplex ? ddsName(f.type) : prim[f.type];
    if (!type) throw new Error(`${t}.${f.name}: type ${f.type}`);
    if (!f.isArray) return `${type} ${f.name};`;
    if (f.arrayLength !== undefined) return `${type} ${f.name}[${f.arrayLength}];`;
    return `sequence<${type}${f.arrayUpperBound ? ", " + f.arrayUpperBound : ""}> ${f.name};`;
  });
  out += `module ${pkg} { module msg { module dds_ {\n  @final struct ${name}_ {\n    ${body.join("\n    ")}\n  };\n}; }; };\n`;
}
process.stdout.write(out);
