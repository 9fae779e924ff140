// rmw_dds_common's graph messages (ParticipantEntitiesInfo on "ros_discovery_info"), which no
// npm package carries (@foxglove/rosmsg-msgs-common has the message packages, not rmw_dds_common):
// the msg files as rmw_dds_common publishes them, Humble's (1.6, Gid char[24]) and Jazzy's (3.1,
// char[16] since Iron), field for field, parsed by @foxglove/rosmsg. withRmwDdsCommon(distro,
// defs) adds them to a distro's definitions.
import { parse } from "@foxglove/rosmsg";

const sep = "\n================================================================================\n";
const text = (gidBytes) =>
  "Gid gid\nNodeEntitiesInfo[] node_entities_info_seq" +
  sep + "MSG: rmw_dds_common/Gid\nchar[" + gidBytes + "] data" +
  sep + "MSG: rmw_dds_common/NodeEntitiesInfo\nstring<=256 node_namespace\nstring<=256 node_name\n" +
  "Gid[] reader_gid_seq\nGid[] writer_gid_seq\n";
const GID_BYTES = { humble: 24, jazzy: 16 };

export function withRmwDdsCommon(distro, defs) {
  const bytes = GID_BYTES[distro];
  if (!bytes) throw new Error(`no rmw_dds_common layout for ${distro}`);
  const [root, ...rest] = parse(text(bytes), { ros2: true });
  const out = { ...defs, "rmw_dds_common/ParticipantEntitiesInfo": { ...root, name: "rmw_dds_common/ParticipantEntitiesInfo" } };
  for (const d of rest) out[d.name] = d;
  return out;
}
