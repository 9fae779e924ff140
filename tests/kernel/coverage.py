"""Line coverage of the kernel-facing files from the kernel test's run alone.

    python3 coverage.py SOURCE_DIR COVERAGE_BUILD_DIR GCOV_PREFIX_DIR

The guest wrote its .gcda files under GCOV_PREFIX_DIR (GCOV_PREFIX) at the build tree's
absolute paths; each is put beside its .gcno in a scratch directory and read with Debian's
gcov. Prints one line per file and the total, then every function of the project's own in
those files that never ran (gcov's function summaries, demangled).
"""
import glob
import os
import re
import shutil
import subprocess
import sys
import tempfile

FILES = ["drivers/platform/linux/*.cpp", "drivers/platform/i2c_dev.cpp", "drivers/platform/spi_dev.cpp", "drivers/devices/i2c_bus_clear.cpp"]


def main():
    top, build, prefix = (os.path.abspath(a) for a in sys.argv[1:4])
    sources = sorted(p for pat in FILES for p in glob.glob(os.path.join(top, pat)))
    scratch = tempfile.mkdtemp(prefix="kcov-")
    total_hit = total = 0
    never = []
    try:
        for src in sources:
            rel = os.path.relpath(src, top)
            name = os.path.basename(src)
            # CMake's object of drivers/platform/linux/x.cpp:
            # <build>/drivers/platform/CMakeFiles/<target>.dir/linux/x.cpp.gcno (the folder of its CMakeLists.txt)
            top_dir = os.path.dirname(rel)
            while not os.path.exists(os.path.join(top, top_dir, "CMakeLists.txt")):
                top_dir = os.path.dirname(top_dir)
            rest = os.path.relpath(rel, top_dir)
            cands = [g for g in glob.glob(os.path.join(build, top_dir, "CMakeFiles", "*.dir", rest + ".gcno"))]
            if not cands:
                print("%-34s no .gcno" % rel)
                continue
            gcno = cands[0]
            d = tempfile.mkdtemp(dir=scratch)
            shutil.copy(gcno, d)
            gcda = prefix + gcno[:-len(".gcno")] + ".gcda"
            if os.path.exists(gcda):
                shutil.copy(gcda, d)
            r = subprocess.run(["gcov", "-n", "-f", "-m", os.path.join(d, os.path.basename(gcno))], cwd=top,
                               capture_output=True, text=True)
            for fn, fpct in re.findall(r"Function '([^']*)'\nLines executed:([\d.]+)%", r.stdout):
                # The project's own functions; the standard library's inlined templates are not ours.
                if float(fpct) == 0.0 and fn.startswith("caracara::"):
                    never.append("%s: %s" % (rel, fn))
            m = re.search(r"File '([^']*%s)'\nLines executed:([\d.]+)%% of (\d+)" % re.escape(rel), r.stdout)
            if not m:
                print("%-34s gcov: no summary (%s)" % (rel, r.stderr.strip()[:100]))
                continue
            pct, n = float(m.group(2)), int(m.group(3))
            hit = round(pct * n / 100)
            total_hit += hit
            total += n
            print("%-34s %6.1f%% of %4d lines%s" % (rel, pct, n, "" if os.path.exists(gcda) else " (never ran)"))
        if total:
            print("%-34s %6.1f%% of %4d lines" % ("total", 100.0 * total_hit / total, total))
        print("functions never executed: %d" % len(never))
        for f in never:
            print("  " + f)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


if __name__ == "__main__":
    main()
