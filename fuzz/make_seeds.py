#!/usr/bin/python3
"""Writes the checked-in seed corpora (fuzz/corpus/<harness>/): a few valid inputs and the
edges of each format, named for what they are. Re-run after changing a harness's input layout:
    python3 fuzz/make_seeds.py"""
import os
import shutil
import struct

HERE = os.path.dirname(os.path.abspath(__file__))


def write(harness, name, data):
    d = os.path.join(HERE, "corpus", harness)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


def packet_seeds():
    def pk(words):
        return struct.pack("<%di" % len(words), *words)
    zero = [0] * 13
    write("packet", "all-zero", pk(zero))
    write("packet", "full-thrust-leds", pk([8850, -8850, 4425, -1, 0, 43, -44, 8850, 0, 0, 255, 128, 0]))
    write("packet", "kill", pk([0] * 8 + [1, 0, 0, 0, 0]))
    write("packet", "kill-raw-minus1", pk([100] * 8 + [-1, 0, 1, 2, 3]))
    write("packet", "kill-and-poweroff", pk([0] * 8 + [7, 1, 0, 0, 0]))
    write("packet", "motor-8851", pk([8851] + [0] * 12))
    write("packet", "motor-int-min", pk([0] * 7 + [-2**31] + [0] * 5))
    write("packet", "poweroff-2", pk([0] * 9 + [2, 0, 0, 0]))
    write("packet", "blue-256-with-kill", pk([0] * 8 + [1, 0, 0, 0, 256]))
    write("packet", "red-minus1", pk([0] * 10 + [-1, 0, 0]))
    write("packet", "short-9-words-kill", pk([0] * 8 + [5]))
    write("packet", "long-14-words", pk(zero + [0]))
    write("packet", "odd-53-bytes", pk(zero) + b"\x00")
    write("packet", "empty", b"")


def main():
    shutil.rmtree(os.path.join(HERE, "corpus"), ignore_errors=True)
    packet_seeds()


if __name__ == "__main__":
    main()
