"""The kernel test's doc check (tests/kernel/write_doc.py --check) on a doc section and run outputs
made here: no QEMU. CTest kernel_doc_check.

A newer point release of the recorded kernel's series passes (and is named); another series, a
scenario failing, missing or added, and a file's coverage outside the tolerance fail; the check
is what tests/kernel/run.sh runs, for the Debian 12 and the Debian 13 sections alike.
"""
import contextlib
import io
import json
import os
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import write_doc  # noqa: E402

SCENARIOS = [("start", "The daemon starts on the kernel's devices."),
             ("kill", "A kill switch edge | kills the vehicle."),
             ("sigterm", "SIGTERM: exit status 0.")]
FILES = [("drivers/platform/i2c_dev.cpp", 90.9, 44), ("drivers/platform/spi_dev.cpp", 90.8, 65)]
OTHER = "drivers/platform/linux/libgpiod2_backend.cpp"


class Run:
    """A run's outputs as tests/kernel/run.sh leaves them, in a temporary directory."""

    def __init__(self, d, scenarios=SCENARIOS, failed=(), no_result=(), files=FILES, never=()):
        self.tsv = os.path.join(d, "scenarios.tsv")
        self.results = os.path.join(d, "results.txt")
        self.cov = os.path.join(d, "coverage.json")
        with open(self.tsv, "w") as f:
            f.write("".join("%s\t%s\n" % s for s in scenarios))
        with open(self.results, "w") as f:
            for name, _ in scenarios:
                if name in no_result:
                    continue
                f.write(("FAIL %s: the wire log shows no zero order\n" % name) if name in failed
                        else "PASS %s (1.2 s)\n" % name)
        cov_files = [{"file": OTHER, "status": "other backend"}]
        for name, pct, lines in files:
            cov_files.append({"file": name, "status": "ran", "percent": pct, "lines": lines,
                              "never": [{"function": fn, "why": why} for f, fn, why in never if f == name]})
        cov_files.sort(key=lambda f: f["file"])
        total = sum(n for _, _, n in files)
        with open(self.cov, "w") as f:
            json.dump({"backend": "libgpiod 1", "files": cov_files,
                       "total": {"percent": round(sum(p * n for _, p, n in files) / total, 1), "lines": total}}, f)

    def args(self, doc, label, kver):
        return [doc, label, self.tsv, self.results, self.cov, kver]


class KernelDocCheck(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.d = self.tmp.name
        self.doc = os.path.join(self.d, "kernel-bridge.md")
        with open(self.doc, "w") as f:
            f.write("# The kernel test\n\nProse the run leaves alone.\n")
        # The record: a run on 6.1.0-56, every scenario passed.
        rec = os.path.join(self.d, "rec")
        os.mkdir(rec)
        self.assertEqual(write_doc.main(Run(rec).args(self.doc, "debian12", "6.1.0-56-amd64")), 0)

    def tearDown(self):
        self.tmp.cleanup()

    def check(self, run, kver="6.1.0-56-amd64", label="debian12"):
        """(exit status, output) of write_doc.py --check for a run."""
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            rc = write_doc.main(["--check"] + run.args(self.doc, label, kver))
        return rc, out.getvalue()

    def run_dir(self, name, **kw):
        d = os.path.join(self.d, name)
        os.mkdir(d)
        return Run(d, **kw)

    def test_record_names_the_kernel_as_information(self):
        with open(self.doc) as f:
            text = f.read()
        self.assertIn("Prose the run leaves alone.", text)
        self.assertIn("Measured last on kernel `6.1.0-56-amd64` (release series 6.1)", text)
        self.assertIn("±3 percentage points", text)
        self.assertNotIn("(kernel 6.1.0-56-amd64)", text)
        # What is written is what is read back.
        self.assertEqual(write_doc.render(write_doc.parse(text, "debian12")),
                         write_doc.section_pattern("debian12").search(text).group(0))

    def test_same_run_passes(self):
        rc, out = self.check(self.run_dir("same"))
        self.assertEqual(rc, 0, out)
        self.assertNotIn("note:", out)

    def test_newer_point_release_passes_and_is_named(self):
        rc, out = self.check(self.run_dir("newer"), kver="6.1.0-57-amd64")
        self.assertEqual(rc, 0, out)
        self.assertIn("booted kernel 6.1.0-57-amd64", out)
        self.assertIn("measured last on 6.1.0-56-amd64", out)

    def test_other_series_fails(self):
        rc, out = self.check(self.run_dir("series"), kver="6.12.117+deb13-amd64")
        self.assertEqual(rc, 1, out)
        self.assertIn("6.12 series", out)
        self.assertIn("6.1 series", out)

    def test_scenario_failing_fails(self):
        rc, out = self.check(self.run_dir("failing", failed=("kill",)))
        self.assertEqual(rc, 1, out)
        self.assertIn("scenario kill did not pass", out)

    def test_scenario_without_result_fails(self):
        rc, out = self.check(self.run_dir("cut", no_result=("sigterm",)))
        self.assertEqual(rc, 1, out)
        self.assertIn("scenario sigterm did not pass: no result", out)

    def test_scenario_missing_fails(self):
        rc, out = self.check(self.run_dir("missing", scenarios=SCENARIOS[:2]))
        self.assertEqual(rc, 1, out)
        self.assertIn("recorded scenarios this run did not run: sigterm", out)

    def test_scenario_added_or_changed_fails(self):
        rc, out = self.check(self.run_dir("added", scenarios=SCENARIOS + [("new", "Something new.")]))
        self.assertEqual(rc, 1, out)
        self.assertIn("not recorded: new", out)
        rc, out = self.check(self.run_dir("changed", scenarios=[SCENARIOS[0], ("kill", "Another claim."), SCENARIOS[2]]))
        self.assertEqual(rc, 1, out)
        self.assertIn("what these scenarios prove is not what is recorded: kill", out)

    def test_coverage_within_tolerance_passes(self):
        files = [(FILES[0][0], FILES[0][1] - 3.0, 44), (FILES[1][0], FILES[1][1] + 2.9, 66)]
        rc, out = self.check(self.run_dir("within", files=files), kver="6.1.0-57-amd64")
        self.assertEqual(rc, 0, out)
        self.assertIn("within ±3 points", out)
        self.assertIn("66 lines instrumented (recorded 65)", out)

    def test_coverage_outside_tolerance_fails(self):
        for name, delta in (("below", -3.1), ("above", +3.2)):
            files = [(FILES[0][0], round(FILES[0][1] + delta, 1), 44), FILES[1]]
            rc, out = self.check(self.run_dir(name, files=files))
            self.assertEqual(rc, 1, out)
            self.assertIn("drivers/platform/i2c_dev.cpp: line coverage", out)
            self.assertIn("outside ±3", out)

    def test_file_not_measured_fails(self):
        rc, out = self.check(self.run_dir("nofile", files=FILES[:1]))
        self.assertEqual(rc, 1, out)
        self.assertIn("spi_dev.cpp: not measured by this run", out)

    def test_no_section_fails(self):
        rc, out = self.check(self.run_dir("d13"), kver="6.12.117+deb13-amd64", label="debian13")
        self.assertEqual(rc, 1, out)
        self.assertIn("no section for debian13", out)

    def test_debian13_section_newer_point_release(self):
        d = self.run_dir("rec13")
        self.assertEqual(write_doc.main(d.args(self.doc, "debian13", "6.12.117+deb13-amd64")), 0)
        rc, out = self.check(self.run_dir("new13"), kver="6.12.118+deb13-amd64", label="debian13")
        self.assertEqual(rc, 0, out)
        rc, out = self.check(self.run_dir("old13"), kver="6.1.0-57-amd64", label="debian13")
        self.assertEqual(rc, 1, out)

    def test_tracked_doc_parses(self):
        """docs/kernel-bridge.md's own sections: each names its kernel and reads back as written."""
        path = os.path.join(HERE, "..", "..", "docs", "kernel-bridge.md")
        with open(path) as f:
            text = f.read()
        for label, series in (("debian12", "6.1"), ("debian13", "6.12")):
            d = write_doc.parse(text, label)
            self.assertIsNotNone(d, label)
            self.assertEqual(write_doc.kernel_series(d["kernel"]), series, label)
            self.assertTrue(d["scenarios"] and d["coverage"] and d["coverage"]["files"], label)
            self.assertEqual(write_doc.render(d), write_doc.section_pattern(label).search(text).group(0), label)

    def test_command_line(self):
        """As run.sh calls it: exit 0 and 1."""
        r = self.run_dir("cli")
        ok = subprocess.run([sys.executable, os.path.join(HERE, "write_doc.py"), "--check"]
                            + r.args(self.doc, "debian12", "6.1.0-57-amd64"), capture_output=True, text=True)
        self.assertEqual(ok.returncode, 0, ok.stdout + ok.stderr)
        bad = subprocess.run([sys.executable, os.path.join(HERE, "write_doc.py"), "--check"]
                             + r.args(self.doc, "debian12", "6.2.0-1-amd64"), capture_output=True, text=True)
        self.assertEqual(bad.returncode, 1, bad.stdout + bad.stderr)


if __name__ == "__main__":
    unittest.main()
