"""A full dive directory: valid dives (tests/dives/overheat.cdive lengthened: its sample blocks
repeated with their times moved on, each block's CRC made again) of about 80 KB each, as many
as fill the recorder's default bound (max_total_mb = 256), named as the recorder names them.
Listing it reads every byte, as a real full directory does: the load of issue 35's Kill-while-
listing test and bench row."""
import os
import struct
import zlib

SOURCE = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SEED = os.path.join(SOURCE, "tests", "dives", "overheat.cdive")
FULL_BYTES = 256 * 1000 * 1000  # max_total_mb = 256 (docs/dive-format.md)
BLOCK_SPAN_100US = 20000         # the seed's two middle blocks hold 2 s of samples


def _block(records):
    return b"DBLK" + struct.pack("<II", len(records), zlib.crc32(records)) + records


def _shifted(records, dt):
    """Every record's time (the u32 its body starts with, 0.1 ms) moved on by dt."""
    out, i = bytearray(), 0
    while i < len(records):
        n = struct.unpack_from("<H", records, i + 1)[0]
        body = bytearray(records[i + 3:i + 3 + n])
        struct.pack_into("<I", body, 0, struct.unpack_from("<I", body, 0)[0] + dt)
        out += records[i:i + 3] + body
        i += 3 + n
    return bytes(out)


def long_dive(repeats=3):
    with open(SEED, "rb") as f:
        src = f.read()
    header_end = 12 + struct.unpack_from("<H", src, 10)[0] + 4
    blocks, at = [], header_end
    while at < len(src):
        n = struct.unpack_from("<I", src, at + 4)[0]
        blocks.append(src[at + 12:at + 12 + n])
        at += 12 + n
    first, middle, last = blocks[0], blocks[1:-1], blocks[-1]
    out = src[:header_end] + _block(first)
    for k in range(repeats):
        out += b"".join(_block(_shifted(b, k * BLOCK_SPAN_100US)) for b in middle)
    return out + _block(_shifted(last, (repeats - 1) * BLOCK_SPAN_100US))


def fill(directory, total=FULL_BYTES):
    """Writes dives into directory until they hold `total` bytes; (count, bytes)."""
    os.makedirs(directory, exist_ok=True)
    dive = long_dive()
    count = -(-total // len(dive))
    for i in range(count):
        # dive-YYYYMMDDTHHMMSS.mmmZ.cdive, one a minute from 2026-01-01.
        day, minute = divmod(i, 24 * 60)
        name = "dive-202601%02dT%02d%02d00.000Z.cdive" % (1 + day, minute // 60, minute % 60)
        with open(os.path.join(directory, name), "wb") as f:
            f.write(dive)
    return count, count * len(dive)
