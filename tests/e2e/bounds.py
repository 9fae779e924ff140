"""The bounds the tests hold the daemon to, read from tests/bounds.json: the one file the
Python, Node (tests/bridge/bounds.mjs) and shell (the system test) tests all read, each bound
there with its promise, the one slack the shared machine needs, its unit and why (the bound
is promised + slack). A test imports a bound by its name (from bounds import
CLIENT_LOSS_ZERO_MS_MAX); a name missing from the file fails the import.

    python3 tests/e2e/bounds.py --shell    every bound as NAME=VALUE, for a shell to source
"""
import json
import math
import pathlib
import sys

FILE = pathlib.Path(__file__).resolve().parent.parent / "bounds.json"


def value(entry):
    """A bound as a test holds to it: the promise and the machine's slack beside it (a floor, kind
    "min", is the promise less the slack)."""
    sign = -1 if entry.get("kind") == "min" else 1
    v = entry["promised"] + sign * entry["slack"]
    return int(v) if isinstance(entry["promised"], int) and isinstance(entry["slack"], int) else float(v)


BOUNDS = {name: value(entry) for name, entry in json.loads(FILE.read_text())["bounds"].items()}
globals().update(BOUNDS)


def shell_value(value):
    """A bound as a shell word: an integer without a point (bash's [ -le ] reads integers only)."""
    return str(int(value)) if float(value).is_integer() else repr(float(value))


if __name__ == "__main__":
    if sys.argv[1:] != ["--shell"]:
        sys.exit("usage: bounds.py --shell")
    for name, value in BOUNDS.items():
        if not math.isfinite(value):
            sys.exit(f"bounds.py: {name} is not a finite number")
        print(f"{name}={shell_value(value)}")
