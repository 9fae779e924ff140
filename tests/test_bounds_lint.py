"""tests/bounds_lint.py's finder of literal timing bounds, on small files written here (CTest
bounds_lint_test): what it must find, and what it must leave alone."""
import os
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bounds_lint  # noqa: E402


def found(ext, text):
    with tempfile.NamedTemporaryFile("w", suffix=ext, delete=False) as f:
        f.write(text)
    try:
        find = {".py": bounds_lint.python_findings, ".mjs": bounds_lint.js_findings, ".sh": bounds_lint.sh_findings}[ext]
        return find(f.name)
    finally:
        os.unlink(f.name)


class PythonTest(unittest.TestCase):
    def test_literal_bounds_found(self):
        src = """
import time
t0 = time.monotonic()
took = time.monotonic() - t0
self.assertLess(took, 10.0)
self.assertGreaterEqual(armed, 0.2)
self.assertLess(max(pings + gets), 500)
pings.append((time.monotonic_ns() - t0) / 1e6)
assert late_ms < 40
self.assertTrue(elapsed_s <= 3)
self.assertLessEqual(until_ns - first, 1500e6)
"""
        lines = [line for line, _ in found(".py", src)]
        self.assertEqual(lines, [5, 6, 7, 9, 10, 11])

    def test_named_bounds_counts_and_conversions_left_alone(self):
        src = """
import time
from bounds import X_MS_MAX
took_ms = (time.monotonic() - t0) * 1000
self.assertLess(took_ms, X_MS_MAX)
self.assertLessEqual(took_ms, timeout_ms + X_MS_MAX)
self.assertGreaterEqual(late_ms, 0)
self.assertGreater(len(samples), 10)
self.assertGreater(count, 5)
rate = sum(sizes) / seconds
self.assertGreater(rate, 1.25 * block)
self.assertLess(at_ns - left, (P + X_MS_MAX) * 1e6)
"""
        self.assertEqual(found(".py", src), [])


class NodeTest(unittest.TestCase):
    def test_literal_bounds_found(self):
        src = ('assert.ok(grown < 32 * 1024, `the bridge grew ${grown} KiB`);\n'
               'assert.ok(offMs <= bound("FAILSAFE_LATENESS_MS_MAX") + 50, `late`);\n'
               'assert.ok(lost.seconds >= P / 1000 - 0.5, "early");\n')
        self.assertEqual([line for line, _ in found(".mjs", src)], [1, 2, 3])

    def test_named_bounds_left_alone(self):
        src = ('assert.ok(worstMs <= bound("CLIENT_LOSS_ZERO_MS_MAX"), `zeroed ${worstMs} ms`);\n'
               'assert.ok(refusals <= 1, `${refusals} refusal events`);\n'
               'assert.ok(state.command_age_ms >= 0);\n')
        self.assertEqual(found(".mjs", src), [])


class ShellTest(unittest.TestCase):
    def test_literal_bounds_found(self):
        src = ('PILOT_LOST_MS=5000\n'
               '[ "$took_ms" -le 250 ]\n')
        self.assertEqual([line for line, _ in found(".sh", src)], [1, 2])

    def test_named_bounds_and_counts_left_alone(self):
        src = ('PILOT_LOST_MS=$PILOT_LOST_PERSISTENCE_MS\n'
               '[ "$ms" -le "$ZEROING_STEP_MS_MAX" ]\n'
               '[ "$(wc -l < f)" -ge 8 ]\n'
               '# [ "$took_ms" -le 250 ] in a comment\n')
        self.assertEqual(found(".sh", src), [])


class TreeTest(unittest.TestCase):
    def test_this_tree_holds(self):
        self.assertEqual(bounds_lint.main(), 0)


if __name__ == "__main__":
    unittest.main()
