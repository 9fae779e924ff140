// The bounds the bridge and cockpit tests assert, read from tests/bounds.json: the one file the
// Python (tests/e2e/bounds.py), Node and shell (the system test) tests all read, each bound there
// with its unit and why. bound(NAME) throws for a name the file does not have.
import fs from "node:fs";

const FILE = new URL("../bounds.json", import.meta.url);
const BOUNDS = JSON.parse(fs.readFileSync(FILE, "utf8")).bounds;

export function bound(name) {
  const entry = BOUNDS[name];
  if (!entry || typeof entry.value !== "number") throw new Error(`tests/bounds.json has no bound ${name}`);
  return entry.value;
}
