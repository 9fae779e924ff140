"""Line coverage of the kernel-facing files from the kernel test's run alone.

    python3 coverage.py SOURCE_DIR COVERAGE_BUILD_DIR GCOV_PREFIX_DIR [JSON_OUT]

The guest wrote its .gcda files under GCOV_PREFIX_DIR (GCOV_PREFIX) at the build tree's
absolute paths; each is put beside its .gcno in a scratch directory and read with the gcov of
the compiler that built them (run it in the root that built them). Prints one line per file
and the total, then every function of the project's own in those files that never ran
(gcov's function summaries, demangled), with why where it is known. JSON_OUT gets the same
figures for tests/kernel/write_doc.py.

CMake builds one libgpiod backend: the other backend's files are listed as such (the Debian 12
run measures v1, the Debian 13 run v2). Exit status 2 when a file of the backend that was
built has no coverage data (no .gcno, no .gcda, or no gcov summary): a file silently left out
is a failure, whatever the percentage.
"""
import glob
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

FILES = ["drivers/platform/linux/*.cpp", "drivers/platform/i2c_dev.cpp", "drivers/platform/spi_dev.cpp",
         "drivers/devices/i2c_bus_clear.cpp"]
V1, V2 = "drivers/platform/linux/libgpiod_", "drivers/platform/linux/libgpiod2_"

# Functions that never run in the guest and why: (file pattern, function pattern, reason).
WHY = [
    (r"", r"^caracara::GpioLine::(event_fd|drain_events|set_in_signal_handler)\(",
     "GpioLine's default, emitted with the backend's classes; every line of this backend overrides it"),
    (r"", r"^caracara::(GpioLine|GpioBackend|DeviceIo)::~(GpioLine|GpioBackend|DeviceIo)\(\)",
     "the interface's inline destructor, a copy GCC emits in this file: the objects are destroyed "
     "through their own classes' destructors"),
    (r"libgpiod2?_backend|libgpiod2_line", r"Libgpiod2?Line::set\(",
     "an input line's set (EPERM, as the kernel would answer): nothing sets an input"),
]


def why(rel, fn):
    for fpat, pat, reason in WHY:
        if re.search(fpat, rel) and re.search(pat, fn):
            return reason
    return ""


def ours(fn):
    """The project's own functions; the standard library's inlined templates are not ours
    (their demangled return type may still start with caracara::)."""
    head = fn.split("(")[0]
    return head.split(" ")[-1].startswith("caracara::")


def gcno_of(top, build, rel):
    # CMake's object of drivers/platform/linux/x.cpp:
    # <build>/drivers/platform/CMakeFiles/<target>.dir/linux/x.cpp.gcno (the folder of its CMakeLists.txt)
    top_dir = os.path.dirname(rel)
    while top_dir and not os.path.exists(os.path.join(top, top_dir, "CMakeLists.txt")):
        top_dir = os.path.dirname(top_dir)
    rest = os.path.relpath(rel, top_dir)
    cands = glob.glob(os.path.join(build, top_dir, "CMakeFiles", "*.dir", rest + ".gcno"))
    return cands[0] if cands else None


def main():
    top, build, prefix = (os.path.abspath(a) for a in sys.argv[1:4])
    json_out = sys.argv[4] if len(sys.argv) > 4 else None
    sources = sorted(p for pat in FILES for p in glob.glob(os.path.join(top, pat)))
    rels = [os.path.relpath(s, top) for s in sources]
    built_v2 = any(gcno_of(top, build, r) for r in rels if r.startswith(V2))
    backend = "libgpiod 2" if built_v2 else "libgpiod 1"
    other = V1 if built_v2 else V2
    scratch = tempfile.mkdtemp(prefix="kcov-")
    total_hit = total = 0
    files, never, missing = [], [], []
    try:
        for rel in rels:
            if rel.startswith(other):
                files.append({"file": rel, "status": "other backend"})
                print("%-42s the other backend (this build: %s)" % (rel, backend))
                continue
            gcno = gcno_of(top, build, rel)
            if not gcno:
                print("%-42s no .gcno: not built with coverage" % rel)
                missing.append(rel)
                files.append({"file": rel, "status": "no .gcno"})
                continue
            d = tempfile.mkdtemp(dir=scratch)
            shutil.copy(gcno, d)
            gcda = prefix + gcno[:-len(".gcno")] + ".gcda"
            ran = os.path.exists(gcda)
            if ran:
                shutil.copy(gcda, d)
            r = subprocess.run(["gcov", "-n", "-f", "-m", os.path.join(d, os.path.basename(gcno))], cwd=top,
                               capture_output=True, text=True)
            m = re.search(r"File '([^']*%s)'\nLines executed:([\d.]+)%% of (\d+)" % re.escape(rel), r.stdout)
            if not m:
                print("%-42s gcov: no summary (%s)" % (rel, r.stderr.strip()[:100]))
                missing.append(rel)
                files.append({"file": rel, "status": "no gcov summary"})
                continue
            if not ran:
                missing.append(rel)
            file_never = []
            for fn, fpct in re.findall(r"Function '([^']*)'\nLines executed:([\d.]+)%", r.stdout):
                if float(fpct) == 0.0 and ours(fn):
                    file_never.append({"function": fn, "why": why(rel, fn)})
            pct, n = float(m.group(2)), int(m.group(3))
            hit = round(pct * n / 100)
            total_hit += hit
            total += n
            never += [dict(f, file=rel) for f in file_never]
            files.append({"file": rel, "status": "ran" if ran else "no .gcda", "percent": pct, "lines": n,
                          "hit": hit, "never": file_never})
            print("%-42s %6.1f%% of %4d lines%s" % (rel, pct, n, "" if ran else " (no .gcda: never ran)"))
        pct_total = 100.0 * total_hit / total if total else 0.0
        if total:
            print("%-42s %6.1f%% of %4d lines (%s)" % ("total", pct_total, total, backend))
        print("functions never executed: %d" % len(never))
        for f in never:
            print("  %s: %s%s" % (f["file"], f["function"], ("\n      why: " + f["why"]) if f["why"] else ""))
        if missing:
            print("coverage: FAIL: no coverage data for %s" % ", ".join(missing))
        if json_out:
            with open(json_out, "w") as f:
                json.dump({"backend": backend, "files": files, "total": {"percent": round(pct_total, 1), "lines": total,
                                                                        "hit": total_hit}, "missing": missing}, f, indent=1)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    return 2 if missing else 0


if __name__ == "__main__":
    sys.exit(main())
