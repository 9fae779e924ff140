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


def csum(b):
    return sum(b) & 0xFF


def seabotix_seeds():
    def codec(reply, mt=0x52, order=b"", motor=0):
        return bytes([len(reply), mt]) + bytes(reply) + bytes(order) + struct.pack("<i", motor)

    def thruster(mt, legacy=False, mux=None, reversed_=False, info=100):
        flags = (1 if legacy else 0) | (2 if mux else 0) | (4 if reversed_ else 0)
        muxb = ((mux[0] - 0x70) | (mux[1] << 3)) if mux else 0
        return bytes([(mt - 0x10) // 2, flags, muxb, info])

    def bus(thrusters, muxregs=(0,) * 8):
        return bytes([len(thrusters) - 1]) + b"".join(thrusters) + bytes(muxregs)

    def order(i, value, faults=(0,)):
        return bytes([(i << 2) | 0]) + struct.pack("<h", value) + bytes(faults)

    def status(i, fields, mode=0, faults=(0,), flip=None):
        # mode 0: well formed from fields; 1: raw bytes; 2: well formed, then one byte flipped.
        b = bytes([(i << 2) | 1, mode]) + bytes(fields)
        if mode == 2:
            b += bytes(flip)
        return b + bytes(faults)

    sb = [0x53, 0x12, 0x00, 0x25, 0xB3, 0x1E]
    write("seabotix", "codec-seabotix-ok", codec(sb + [csum(sb)]) + bus([thruster(0x52)]))
    lg = [0x55, 0x20, 0x40]
    write("seabotix", "codec-legacy-ok", codec(lg + [csum(lg)], mt=0x54, motor=-8850) + bus([thruster(0x54, True)]))
    write("seabotix", "codec-bad-checksum", codec(sb + [csum(sb) ^ 1], order=[0x80, 100, (0x52 + 0x80 + 100) & 0xFF]))
    write("seabotix", "codec-idle-high", codec([0xFF] * 7, motor=8851))
    write("seabotix", "codec-order-0x7f", codec([], order=[0x7F, 100, (0x52 + 0x7F + 100) & 0xFF], motor=-43))
    write("seabotix", "codec-motor-int-min", codec([], motor=-2**31))
    # The vehicle: two same-address thrusters behind two muxes, one more on a second channel,
    # one legacy thruster on the trunk; the muxes start with stale channels enabled.
    four = bus([thruster(0x52, mux=(0x70, 0)), thruster(0x52, mux=(0x71, 0)),
                thruster(0x56, mux=(0x70, 1), reversed_=True), thruster(0x54, legacy=True)],
               muxregs=(0x05, 0x04, 0, 0, 0, 0, 0, 0))
    ops = (order(0, 4425) + order(1, -8850) + order(2, 1000) + order(3, 8850) +
           status(0, [0x12, 0x00, 0x25, 0xB3, 0x1E]) + status(1, [0x12, 0x09, 0x25, 0x40, 0x50]) +
           status(2, [0x02, 0x1F, 0x00, 0xE6, 0x1E]) + status(3, [0x41, 0x9C]) +
           status(0, [0x12, 0x00, 0x25, 0xB3, 0x1E], mode=2, flip=[3, 0x10]) +
           status(1, [0x53, 0x12, 0x00, 0x25, 0xB3, 0x1E, 0x00], mode=1))
    write("seabotix", "bus-four-thrusters", codec([]) + four + ops)
    faults = (order(0, 100, faults=(0, 0, 0x0C)) +            # disable 0x71 fails but latches
              order(1, 200, faults=(0, 4)) +                  # the mux write is NACKed
              order(1, 200, faults=(0, 0, 5)) +               # the thruster times out
              bytes([(1 << 2) | 2]) + order(1, 300) +         # mux 0x71 browns out: NACK
              order(1, 300) + status(3, [0x20, 0x80], faults=(6,)) +
              bytes([3]) + order(2, 9000) + order(2, -32768) + status(2, [0x22, 0x01, 0x10, 0x7F, 0x30], faults=(7,)))
    write("seabotix", "bus-faults", codec([]) + four + faults)
    write("seabotix", "bus-conflict", codec([]) + bus([thruster(0x52), thruster(0x52, mux=(0x70, 0))]) + order(0, 1))
    write("seabotix", "bus-mux-address", codec([]) + bus([thruster(0xE0), thruster(0x52, mux=(0x70, 0))]))


def teensy_seeds():
    size = {1: 3, 2: 4, 3: 6, 4: 6, 5: 3, 6: 4, 7: 5, 8: 7, 9: 5}
    h16 = lambda v: struct.pack("<h", v)

    def ack(cmd, before=None):   # the Teensy acks: bytes before the ack slot, then the command
        b = before if before is not None else [0] * (size[cmd] - 1)
        return bytes([0]) + bytes(b)

    def busy(cmd):
        return bytes([1]) + bytes(size[cmd] - 1)

    def raw(b):
        return bytes([2]) + bytes(b)

    fail = bytes([3])
    short = bytes([4])

    def link(flags=2, busy_retries=10, servos=4, sensors=4):
        return bytes([flags, busy_retries, servos, sensors])

    # The pure decoder: Confirm's reply "finished" (0xFF in the answer slot is data, not busy).
    pure_ok = bytes([0, 3, 0x00, 0xFF, 0x01])
    pure_torn = bytes([6, 3, 0x07, 0x00, 0x00])
    ops = (bytes([0]) + h16(100) + h16(-100) + ack(2) +
           bytes([1, 0]) + h16(1500) + busy(3) + ack(3) +
           bytes([2, 1]) + struct.pack("<d", -3.14159) + ack(4) +
           bytes([3]) + h16(255) + ack(5) +
           bytes([4]) + h16(3) + h16(180) + ack(6) +
           bytes([5]) + h16(1) + ack(7, [0, 0, 0xE8, 0x03]) +
           bytes([6]) + h16(2) + ack(8, [0, 0] + list(struct.pack("<f", 0.5))) +
           bytes([7]) + h16(255) + h16(0) + h16(128) + ack(9) +
           bytes([8, 0]) + ack(1, [0xFF]))
    write("teensy", "link-every-command", pure_ok + link() + ops)
    refused = (bytes([0]) + h16(128) + h16(0) + bytes([1, 1]) + struct.pack("<d", float("nan")) +
               bytes([2, 1]) + struct.pack("<d", 1e39) + bytes([3]) + h16(-1) +
               bytes([4]) + h16(4) + h16(0) + bytes([4]) + h16(0) + h16(181) + bytes([5]) + h16(4) +
               bytes([6]) + h16(3) + bytes([7]) + h16(256) + h16(0) + h16(0))
    write("teensy", "link-refused-arguments", pure_torn + link() + refused)
    errors = (bytes([1, 0]) + h16(700) + raw([3, 0, 0, 0, 0, 0x00]) +         # Turn: link error, never resent
              bytes([0]) + h16(5) + h16(5) + raw([0, 0, 0, 0x42]) + ack(2) +   # Set Speed: resent once
              bytes([0]) + h16(5) + h16(5) + busy(2) + busy(2) + busy(2) +      # busy, exhausted after 2
              bytes([5]) + h16(0) + fail + bytes([5]) + h16(0) + short +
              bytes([6]) + h16(0) + ack(8, [0, 0, 0, 0, 0x80, 0x7F]))           # +Inf: bad answer
    write("teensy", "link-errors-per-byte", bytes([0x08, 3, 0x42, 0x04, 0x00, 0x08]) + link(flags=0x13, busy_retries=2) +
          errors)
    hs = (bytes([9]) + struct.pack("<I", 20_000_000) + bytes([0]) + struct.pack("<I", 1_000_000_000) + bytes([3]) +
          bytes([0]) + struct.pack("<I", 1000) +
          bytes([0]) + ack(1, [0x00]) +                        # poll: still turning
          bytes([0]) +                                         # too early: wait
          bytes([1]) + struct.pack("<I", 20_000_001) +
          bytes([0]) + ack(1, [0xFF]) +                        # finished
          bytes([2, 0, 0x42]) +                                # a stray answer
          bytes([0]) + busy(1) + ack(1, [0x00]) +              # the acknowledgement, after a busy
          bytes([0]))                                          # done
    write("teensy", "handshake-finished", pure_ok + link() + hs)
    hs_timeout = (bytes([9]) + struct.pack("<I", 0) + bytes([1]) + struct.pack("<Q", 2**64 - 1) + bytes([0]) +
                  bytes([1]) + struct.pack("<Q", 2**64 - 5) +
                  bytes([0]) + ack(1, [0xFF]) + bytes([0]) + fail + bytes([1]) + struct.pack("<I", 10) + bytes([0]) +
                  bytes([3]) + bytes([0]) + ack(1, [0x07]))
    write("teensy", "handshake-saturated-ack-fails", pure_ok + link() + hs_timeout)
    hs_short = (bytes([9]) + struct.pack("<I", 1000) + bytes([0]) + struct.pack("<I", 5000) + bytes([2]) +
                bytes([0]) + struct.pack("<I", 0) + bytes([0]) + ack(1, [0]) + bytes([1]) + struct.pack("<I", 6000) +
                bytes([0]) + bytes([0]))
    write("teensy", "handshake-timeout", pure_ok + link() + hs_short)


def config_seeds():
    with open(os.path.join(HERE, "..", "daemon", "caracarad.toml.example")) as f:
        write("config", "example", f.read())
    write("config", "empty", "")
    muxed = "".join('[[thruster]]\naddress = 0x52\nvariant = "%s"\nmux_address = 0x%x\nmux_channel = %d\n'
                    % ("legacy" if i % 2 else "seabotix", 0x70 + i // 4, i % 4) for i in range(8))
    write("config", "eight-muxed", "[i2c]\ndevice = \"/dev/i2c-1\"\nclock_hz = 400000\n" + muxed)
    write("config", "gpio-recovery", """[gpio]
kill_switch = { chip = "gpiochip0", line = 17, active_low = true }
kill_output = { line = "KILL_OUT" }
power_off_output = { chip = "gpiochip1", line = 4 }
scl = { line = 3 }
sda = { line = 2 }
[recovery]
enabled = true
attempts = 10
driver_id = "fe804000.i2c"
[control]
profile = "air"
budget_policy = "reject"
loop_rate_hz = 0
[profiles]
air = 0.15
water = 1
""")
    write("config", "every-error", """[i2c]
device = "dev/i2c-1"
clock_hz = 99999999999999999999
timeout_ms = -1
retries = "3"
[spi]
servos = 257
speed_hz = 1e6
[[thruster]]
address = 0x53
mux_address = 0xE0
mux_channel = 4
[mixing]
matrix = [[1, 2], "x", [nan, inf, -inf, 1.5, 0, 0]]
[control]
profile = "space"
arm_at_start = 1
status_reads_per_tick = 0
[gpio]
scl = { line = 3 }
kill_switch = { line = 3 }
[recovery]
enabled = true
driver_id = "a b"
[profiles]
bad = 0
worse = "x"
[unknown]
cntrol = 1
""")
    write("config", "sim-section", '[sim]\nrealistic_timing = true\nrebind_delay_ms = 70000\n[[thruster]]\naddress = 0x54\nbrushless = false\n')
    write("config", "syntax-error", '[i2c\ndevice = "/dev/i2c-1"\n[[thruster]]\naddress = 0x52\naddress = 0x54\n')
    write("config", "duplicate-mux-route", "".join('[[thruster]]\naddress = 0x%x\nmux_address = 0x70\nmux_channel = 0\n'
                                                  % (0x52 if i < 2 else 0x52 + 2 * i) for i in range(8)))
    write("config", "utf8-keys", '"ключ" = 1\n[profiles]\n"водa" = 0.5\n[control]\nprofile = "водa"\n')


def sim_request_seeds():
    seq = [0]

    def hdr(op):
        seq[0] += 1
        return struct.pack("<IHHI", 0x4D495343, op, 0, seq[0])

    def s(text):
        b = text.encode()
        return struct.pack("<I", len(b)) + b

    def req(body):
        return struct.pack("<H", len(body)) + body

    OPEN, CLOSE, I2C, SPI, IOCTL, WRITE, GREQ, GGET, GSET, GREL, GWATCH = range(1, 12)
    opens = (req(hdr(OPEN) + s("/dev/i2c-1") + struct.pack("<i", 2)) +            # handle 3
             req(hdr(OPEN) + s("/dev/spidev0.0") + struct.pack("<i", 2)) +        # handle 4
             req(hdr(OPEN) + s("/sys/bus/platform/drivers/i2c-bcm2835/unbind") + struct.pack("<i", 1)) +  # 5
             req(hdr(OPEN) + s("/sys/bus/platform/drivers/i2c-bcm2835/bind") + struct.pack("<i", 1)))     # 6

    def i2c(msgs):
        b = hdr(I2C) + struct.pack("<iI", 3, len(msgs))
        for addr, rd, data in msgs:
            b += struct.pack("<HHH", addr, 1 if rd else 0, data if rd else len(data))
            if not rd:
                b += bytes(data)
        return req(b)

    def spi(xfers):
        b = hdr(SPI) + struct.pack("<iI", 4, len(xfers))
        for tx, rx in xfers:
            b += struct.pack("<IIHBBBB", len(tx), 500000, 0, 8, 0, 1, 1 if rx else 0) + bytes(tx)
        return req(b)

    def ioctl(h, request, value):
        return req(hdr(IOCTL) + struct.pack("<iQQ", h, request, value))

    I2C_FUNCS, I2C_TIMEOUT, SPI_WR_MODE, SPI_RD_SPEED = 0x0705, 0x0702, 0x40016B01, 0x80046B04
    order = [0x80, 100, (0x52 + 0x80 + 100) & 0xFF]
    thrusters = (i2c([(0x29, False, order)]) + i2c([(0x29, True, 7)]) + i2c([(0x2B, False, order), (0x2B, True, 7)]) +
                 i2c([(0x70, False, [0x04])]) + i2c([(0x10, True, 1)]))
    teensy = spi([([0x02, 10, 0xF6, 0], True)]) + spi([([0x01, 0, 0], True)]) + spi([([0x07, 0, 0, 0, 0], True)]) + \
        spi([([0x08], True), ([0], True), ([0, 0, 0, 0, 0], True)])
    ioctls = (ioctl(3, I2C_FUNCS, 0) + ioctl(3, I2C_TIMEOUT, 10) + ioctl(4, SPI_WR_MODE, 0) + ioctl(4, SPI_RD_SPEED, 0) +
              ioctl(5, I2C_FUNCS, 0) + ioctl(3, 0xDEAD, 0))
    write("sim_request", "devices", opens + thrusters + teensy + ioctls + req(hdr(CLOSE) + struct.pack("<i", 3)) +
          req(hdr(CLOSE) + struct.pack("<i", 3)))
    gpio = (req(hdr(GREQ) + s("gpiochip0") + s("") + struct.pack("<iBBB", 27, 2, 0, 1)) +            # 3
            req(hdr(GREQ) + s("gpiochip0") + s("KILL_SWITCH") + struct.pack("<iBBB", -1, 1, 1, 0)) +  # 4
            req(hdr(GREQ) + s("/dev/gpiochip0") + s("") + struct.pack("<iBBB", 3, 3, 0, 1)) +        # 5
            req(hdr(GSET) + struct.pack("<iB", 3, 0)) + req(hdr(GGET) + struct.pack("<i", 4)) +
            req(hdr(GSET) + struct.pack("<iB", 5, 0)) + req(hdr(GSET) + struct.pack("<iB", 5, 1)) +
            req(hdr(GSET) + struct.pack("<iB", 4, 1)) + req(hdr(GREL) + struct.pack("<i", 5)) +
            req(hdr(GWATCH) + s("gpiochip0") + s("KILL_SWITCH") + struct.pack("<i", -1)))
    write("sim_request", "gpio", gpio)
    recovery = (opens + req(hdr(WRITE) + struct.pack("<iI", 5, 13) + b"fe804000.i2c\n") +
                i2c([(0x29, True, 7)]) + req(hdr(WRITE) + struct.pack("<iI", 6, 12) + b"fe804000.i2c") +
                req(hdr(WRITE) + struct.pack("<iI", 6, 12) + b"fe804000.i2c") + req(hdr(WRITE) + struct.pack("<iI", 3, 1) + b"x"))
    write("sim_request", "unbind-bind", recovery)
    malformed = (opens + req(hdr(OPEN) + s("/dev/i2c-1")) + req(hdr(CLOSE) + struct.pack("<iB", 3, 0)) +
                 req(struct.pack("<IHHI", 0x4D495343, 0x8003, 0, 9)) + req(struct.pack("<IHH", 0x4D495343, 3, 0)) +
                 req(struct.pack("<IHHI", 0x12345678, 1, 0, 1)) + req(hdr(12) + struct.pack("<iQ", 0, 0)) +
                 req(hdr(I2C) + struct.pack("<iI", 3, 0)) + req(hdr(I2C) + struct.pack("<iI", 3, 43)) +
                 req(hdr(I2C) + struct.pack("<iIHHH", 3, 1, 0x29, 1, 8193)) +
                 req(hdr(SPI) + struct.pack("<iI", 4, 1) + struct.pack("<IIHBBBB", 8193, 0, 0, 8, 0, 0, 1)) +
                 req(hdr(SPI) + struct.pack("<iI", 4, 513)) + req(b"") +
                 req(hdr(I2C) + struct.pack("<iIHHH", 4, 1, 0x29, 0, 1) + b"\x80"))
    write("sim_request", "malformed", malformed)
    big = opens + i2c([(0x29, True, 8192)] * 8) + spi([([0] * 4096, True), ([0] * 4096, True)])
    write("sim_request", "reply-too-long", big)


def bridge_seeds():
    def frame(data, binary=False):
        data = data if isinstance(data, bytes) else data.encode()
        return struct.pack("<BH", 1 if binary else 0, len(data)) + data

    def message(channel, body):
        return frame(struct.pack("<BI", 1, channel) + body.encode(), True)

    adv = frame('{"op":"advertise","channels":[{"id":1,"topic":"/command/motion","encoding":"json","schemaName":"m"},'
                '{"id":2,"topic":"/command/thrust","encoding":"json","schemaName":"t"},'
                '{"id":3,"topic":"/command/leds","encoding":"json","schemaName":"l"},'
                '{"id":4,"topic":"/command/profile","encoding":"json","schemaName":"p"},'
                '{"id":5,"topic":"/command/kill","encoding":"json","schemaName":"k"},'
                '{"id":6,"topic":"/command/drive","encoding":"json","schemaName":"d"}]}')
    write("bridge", "subscribe-all", frame('{"op":"subscribe","subscriptions":[' +
                                           ",".join('{"id":%d,"channelId":%d}' % (i, i) for i in range(1, 15)) + "]}"))
    write("bridge", "commands", adv + message(1, '{"linear":{"x":0.5,"y":0,"z":0},"angular":{"x":0,"y":0,"z":-0.25}}') +
          message(2, '{"values":[1,2,3,4,5,6,7,8]}') + message(3, '{"red":1,"green":2,"blue":3}') +
          message(4, '{"name":"water"}') + message(5, "{}") + message(6, '{"forward":0.5,"turn_right":-0.25}'))
    write("bridge", "bad", frame("not json") + frame('{"op":"nope"}') + frame(b"\x09\x00", True) +
          message(9, "{}") + adv + message(2, '{"values":[1]}') + message(1, '{"x":0.5}') +
          message(6, '{"surge":1}') + frame('{"op":"unsubscribe","subscriptionIds":[7]}'))


def main():
    shutil.rmtree(os.path.join(HERE, "corpus"), ignore_errors=True)
    packet_seeds()
    seabotix_seeds()
    teensy_seeds()
    config_seeds()
    sim_request_seeds()
    bridge_seeds()


if __name__ == "__main__":
    main()
