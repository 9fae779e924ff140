// The bounds the bridge and cockpit tests assert, read from tests/bounds.json: the one file the
// Python (tests/e2e/bounds.py), Node and shell (the system test) tests all read, each bound there
// with its promise, the slack the shared machine needs, its unit and why (promised + slack). bound(NAME) throws for a name the file does not have.
import fs from "node:fs";

const FILE = new URL("../bounds.json", import.meta.url);
const BOUNDS = JSON.parse(fs.readFileSync(FILE, "utf8")).bounds;

// A bound as a test holds to it: the promise and the machine's slack beside it (a floor, kind
// "min", is the promise less the slack).
export function bound(name) {
  const entry = BOUNDS[name];
  if (!entry || typeof entry.promised !== "number" || typeof entry.slack !== "number")
    throw new Error(`tests/bounds.json has no bound ${name}`);
  return entry.promised + (entry.kind === "min" ? -entry.slack : entry.slack);
}
