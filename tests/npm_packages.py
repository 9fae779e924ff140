#!/usr/bin/python3
"""The npm packages of a Node test directory (tests/bridge, tests/ros, fuzz/node), installed before any test
isolates itself: CTest's setup tests npm_bridge and npm_ros (FIXTURES_SETUP, tests/CMakeLists.txt)
and tests/system/debian13.sh run this, outside any network namespace; the tests themselves only
check (tests/e2e/harness.py npm_ci), and never reach for the network.

    npm_packages.py DIR...            install DIR's node_modules as DIR/package-lock.json pins them
                                      (npm ci), unless they are already up to date
    npm_packages.py --check DIR...    exit 1, naming the fixture, unless they are up to date

Up to date: DIR/node_modules/.package-lock.json (npm's record of what it installed) is not older
than DIR/package-lock.json and pins the same version of every package the lock pins. Installed
only from the lock file (npm ci), with the cache /var/cache/caracara-npm kept between runs.
Exit 77 (CTest: skipped) when npm is missing outside CI; under CI (CI=true) that fails.
"""
import json
import os
import shutil
import subprocess
import sys

NPM_CACHE = "/var/cache/caracara-npm"
# Which CTest setup test installs which directory's packages.
FIXTURE = {"bridge": "npm_bridge", "ros": "npm_ros", "node": "npm_fuzz"}


def fixture(here):
    return FIXTURE.get(os.path.basename(os.path.normpath(here)), "npm_packages.py")


def pinned(path):
    """{package path: version} of an npm lock file (lockfileVersion 2 or 3), the root left out."""
    with open(path) as f:
        data = json.load(f)
    return {k: v.get("version") for k, v in data.get("packages", {}).items() if k}


def stale(here):
    """Why DIR's node_modules are not what its package-lock.json pins (None when they are)."""
    lock = os.path.join(here, "package-lock.json")
    stamp = os.path.join(here, "node_modules", ".package-lock.json")
    if not os.path.exists(stamp):
        return "%s has no node_modules" % here
    if os.path.getmtime(stamp) < os.path.getmtime(lock):
        return "%s/node_modules is older than its package-lock.json" % here
    want, have = pinned(lock), pinned(stamp)
    # npm's record leaves out the optional packages this platform does not take: those may be
    # missing, every other one must be there, and each one there at the version pinned.
    with open(lock) as f:
        optional = {k for k, v in json.load(f).get("packages", {}).items() if v.get("optional")}
    wrong = sorted(k for k, v in want.items() if have.get(k, v if k in optional else None) != v)
    if wrong:
        return "%s/node_modules does not hold what package-lock.json pins (%s%s)" % (
            here, ", ".join(wrong[:3]), ", ..." if len(wrong) > 3 else "")
    return None


def install(here):
    why = stale(here)
    if why is None:
        print("%s: node_modules up to date with package-lock.json" % here)
        return 0
    print("%s: %s; npm ci (cache %s)" % (here, why, NPM_CACHE))
    if not shutil.which("npm"):
        if os.environ.get("CI") == "true":
            print("FAIL: npm is needed to install %s's packages (scripts/deps.sh)" % here)
            return 1
        print("SKIP: npm is needed to install %s's packages (scripts/deps.sh)" % here)
        return 77
    os.makedirs(NPM_CACHE, exist_ok=True)
    r = subprocess.run(["npm", "ci", "--cache", NPM_CACHE, "--no-audit", "--no-fund", "--prefer-offline"],
                       cwd=here, stdout=subprocess.DEVNULL)
    if r.returncode != 0:
        print("FAIL: npm ci in %s exited %d" % (here, r.returncode))
        return 1
    why = stale(here)
    if why:
        print("FAIL: after npm ci, %s" % why)
        return 1
    return 0


def main(argv):
    check = argv[:1] == ["--check"]
    dirs = [os.path.abspath(d) for d in (argv[1:] if check else argv)]
    if not dirs:
        print(__doc__)
        return 2
    rc = 0
    for d in dirs:
        if check:
            why = stale(d)
            if why:
                print("%s: run the CTest setup test %s (tests/npm_packages.py %s) first" % (why, fixture(d), d))
                rc = 1
        else:
            r = install(d)
            rc = r if rc == 0 else rc
    return rc


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
