/* SPDX-License-Identifier: (GPL-2.0 WITH Linux-syscall-note) OR MIT */
/*
 * The wire format of /dev/caracara-bridge, shared by the test kernel module
 * (tests/kernel/module/caracara_bridge.c) and caracara-sim's front end
 * (sim/kernel_bridge.cpp). docs/kernel-bridge.md describes the protocol.
 *
 * Every message, either way, is one header followed by `len - sizeof(header)` bytes of
 * payload, in the machine's byte order. One read() returns exactly one request; one
 * write() carries exactly one message.
 */
#ifndef CARACARA_KERNEL_BRIDGE_ABI_H
#define CARACARA_KERNEL_BRIDGE_ABI_H

#include <linux/types.h>

#define CCB_DEVICE_NAME "caracara-bridge"
#define CCB_VERSION 1
/* The largest message either way: 42 I2C messages of 8192 bytes plus headers fit. */
#define CCB_MAX_MESSAGE (512 * 1024)

struct ccb_header {
	__u32 len;    /* whole message, header included */
	__u32 seq;    /* request number; a reply repeats it; 0 for notifications */
	__u16 type;   /* enum ccb_type */
	__u16 arg;    /* per type: the GPIO operation, the bind state */
	__s32 result; /* replies: >= 0 or -errno; requests: 0 */
};

enum ccb_type {
	/* kernel -> user space: requests, each answered by one reply (type | CCB_REPLY) */
	CCB_I2C_XFER = 1,  /* master_xfer of the I2C adapter */
	CCB_SPI_MSG = 2,   /* transfer_one_message of the SPI controller */
	CCB_GPIO = 3,      /* a gpio_chip callback; arg = enum ccb_gpio_op */
	CCB_I2C_BIND = 4,  /* the adapter's platform driver probed (arg 1) or was removed (arg 0) */
	/* user space -> kernel: notifications, never answered */
	CCB_GPIO_LEVEL = 16, /* an input line's level changed on the wire */
	CCB_REPLY = 0x8000,
};

/* CCB_I2C_XFER: u32 count, then per message a ccb_i2c_msg followed (writes only) by its
 * `len` bytes. Reply: result = count or -errno; payload = the bytes of every read message,
 * in order, each exactly `len` long (only when result >= 0). */
struct ccb_i2c_msg {
	__u16 addr;  /* 7-bit address (10-bit with I2C_M_TEN) */
	__u16 flags; /* I2C_M_RD, I2C_M_TEN, ... as in struct i2c_msg */
	__u16 len;
	__u16 pad;
};

/* CCB_SPI_MSG: a ccb_spi_msg, then per transfer a ccb_spi_xfer followed (has_tx only) by
 * its `len` bytes. Reply: result = total bytes or -errno; payload = the MISO bytes of every
 * transfer with want_rx, in order. */
struct ccb_spi_msg {
	__u32 mode;          /* spi_device mode bits: SPI_CPHA, SPI_CPOL, SPI_LSB_FIRST, ... */
	__u32 max_speed_hz;  /* the device's max_speed_hz */
	__u16 chip_select;
	__u8 bits_per_word;  /* the device's default */
	__u8 pad;
	__u32 count;         /* transfers */
};

struct ccb_spi_xfer {
	__u32 len;
	__u32 speed_hz;
	__u16 delay_usecs; /* delay after the transfer */
	__u8 bits_per_word;
	__u8 cs_change;
	__u8 has_tx;
	__u8 want_rx;
	__u16 pad;
};

/* CCB_GPIO: payload ccb_gpio; reply result: the physical level for GET, else 0, or -errno. */
enum ccb_gpio_op {
	CCB_GPIO_REQUEST = 1, /* the line is being requested; -errno refuses it */
	CCB_GPIO_FREE = 2,
	CCB_GPIO_INPUT = 3,   /* direction input */
	CCB_GPIO_OUTPUT = 4,  /* direction output, value; flags say open drain */
	CCB_GPIO_SET = 5,     /* physical value */
	CCB_GPIO_GET = 6,
};
#define CCB_GPIO_OPEN_DRAIN 1u

struct ccb_gpio {
	__u32 offset;
	__u32 value;
	__u32 flags;
};

/* CCB_GPIO_LEVEL (user -> kernel): the physical level of `offset` is now `value`. The
 * kernel keeps it, fires the line's interrupt if the edge matches its trigger, and answers
 * gpio get() for lines with an interrupt in use from it (the handler reads the level
 * while the simulator is still writing). */

#endif
