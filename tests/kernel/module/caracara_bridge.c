// SPDX-License-Identifier: GPL-2.0
/*
 * caracara_bridge: test-only I2C adapter, SPI controller and GPIO chip whose every
 * transfer and line operation is forwarded to a user-space process (caracara-sim
 * --kernel-bridge) through the character device /dev/caracara-bridge.
 *
 *   - I2C: platform driver "caracara-i2c" on platform device "caracara-i2c", a raw I2C
 *     adapter (I2C_FUNC_I2C) numbered i2c_bus (default 1: /dev/i2c-1 through i2c-dev).
 *     Unbind/bind it with /sys/bus/platform/drivers/caracara-i2c/{unbind,bind}.
 *   - SPI: controller spi_bus (default 0) with one device at chip select 0 bound to
 *     spidev through driver_override: /dev/spidev0.0.
 *   - GPIO: a 28-line chip (GPIO0..GPIO27, like a Raspberry Pi header) whose lines can
 *     raise edge interrupts (nested, threaded), so GPIO v1 line events work.
 *
 * Faults the kernel itself reports (tests/kernel/scenarios.py writes them to
 * /sys/module/caracara_bridge/parameters/): each *_fail_count requests fail, then the part
 * works again.
 *   - i2c_fail_errno, i2c_fail_addr (-1 any), i2c_fail_count: a transfer to that address
 *     fails with -i2c_fail_errno without reaching the server; errno 0 = a short transfer
 *     (one message fewer than asked, as a controller that stopped early reports it).
 *   - i2c_func_fail_count: I2C_FUNCS answers without I2C_FUNC_I2C.
 *   - i2c_probe_errno, i2c_probe_fail_count: binding the adapter's driver fails.
 *   - spi_silent_count: an SPI message completes without reaching the server, MISO reading
 *     all zeros (a Teensy that stopped answering: nothing drives the line).
 *   - spi_fail_errno, spi_fail_count: an SPI message refused; spi_setup_fail_count: the
 *     controller refuses a mode/word size/speed (spidev's SPI_IOC_WR_* ioctls; never the
 *     setup of the probe's own device).
 *   - gpio_fail_errno, gpio_fail_offset, gpio_fail_op (CCB_GPIO_* op, 0 any), gpio_fail_count,
 *     gpio_fail_skip: after gpio_fail_skip matching operations, a line operation fails (errno
 *     0: a GET reads low); a get by the kernel's own edge handler is never failed.
 *
 * Protocol: sim/kernel_bridge_abi.h and docs/kernel-bridge.md. One request is in flight
 * at a time; with no server attached every request fails with -ENXIO, and a server that
 * does not answer within 5 s fails it with -ETIMEDOUT.
 */
#include <linux/completion.h>
#include <linux/fs.h>
#include <linux/gpio/driver.h>
#include <linux/i2c.h>
#include <linux/interrupt.h>
#include <linux/irq.h>
#include <linux/miscdevice.h>
#include <linux/module.h>
#include <linux/mutex.h>
#include <linux/platform_device.h>
#include <linux/property.h>
#include <linux/sched.h>
#include <linux/poll.h>
#include <linux/slab.h>
#include <linux/spi/spi.h>
#include <linux/spinlock.h>
#include <linux/uaccess.h>
#include <linux/version.h>
#include <linux/vmalloc.h>
#include <linux/wait.h>

#include "kernel_bridge_abi.h"

/*
 * Built for Debian 12's kernel (6.1) and Debian 13's (6.12). Linux 6.11 made a platform
 * driver's remove return nothing; 6.3 made a SPI device's chip select an array (read and set
 * through spi_get_chipselect/spi_set_chipselect); the driver override of a SPI device moved
 * to its struct device (device_set_driver_override; Kbuild defines
 * CCB_DEVICE_DRIVER_OVERRIDE where the headers have it, Debian 13's among them).
 */
#if LINUX_VERSION_CODE >= KERNEL_VERSION(6, 11, 0)
#define CCB_REMOVE_RET void
#define CCB_REMOVE_OK
#else
#define CCB_REMOVE_RET int
#define CCB_REMOVE_OK 0
#endif
#if LINUX_VERSION_CODE >= KERNEL_VERSION(6, 3, 0)
#define ccb_chip_select(spi) spi_get_chipselect(spi, 0)
/*
 * One chip select: the array's other entries unused (0xFF, the core's SPI_INVALID_CS), or
 * 6.12's spi_add_device takes them for a second use of chip select 0 (-EBUSY, "chipselect 0
 * already in use"); from 6.8 the mask of the ones in use says entry 0.
 */
static inline void ccb_set_chip_select(struct spi_device *spi, u8 cs)
{
	u8 idx;

	for (idx = 0; idx < SPI_CS_CNT_MAX; idx++)
		spi_set_chipselect(spi, idx, idx ? 0xFF : cs);
#if LINUX_VERSION_CODE >= KERNEL_VERSION(6, 8, 0)
	spi->cs_index_mask = BIT(0);
#endif
}
#else
#define ccb_chip_select(spi) ((spi)->chip_select)
#define ccb_set_chip_select(spi, cs) ((spi)->chip_select = (cs))
#endif

static int i2c_bus = 1;
module_param(i2c_bus, int, 0444);
MODULE_PARM_DESC(i2c_bus, "I2C adapter number (/dev/i2c-N)");
static int spi_bus = 0;
module_param(spi_bus, int, 0444);
MODULE_PARM_DESC(spi_bus, "SPI bus number (/dev/spidevB.0)");
static unsigned int timeout_ms = 5000;
module_param(timeout_ms, uint, 0644);
MODULE_PARM_DESC(timeout_ms, "how long a request waits for the user-space server");

#define CCB_NGPIO 28

/* ---- injected faults (see the top of the file) ---- */

static DEFINE_SPINLOCK(ccb_fault_lock);
static int i2c_fail_errno;
module_param(i2c_fail_errno, int, 0644);
static int i2c_fail_addr = -1;
module_param(i2c_fail_addr, int, 0644);
static int i2c_fail_count;
module_param(i2c_fail_count, int, 0644);
static int i2c_func_fail_count;
module_param(i2c_func_fail_count, int, 0644);
static int i2c_probe_errno = EIO;
module_param(i2c_probe_errno, int, 0644);
static int i2c_probe_fail_count;
module_param(i2c_probe_fail_count, int, 0644);
static int spi_fail_errno = EIO;
module_param(spi_fail_errno, int, 0644);
static int spi_fail_count;
module_param(spi_fail_count, int, 0644);
static int spi_setup_fail_count;
module_param(spi_setup_fail_count, int, 0644);
static int spi_silent_count;
module_param(spi_silent_count, int, 0644);
static int gpio_fail_errno = EIO;
module_param(gpio_fail_errno, int, 0644);
static int gpio_fail_offset = -1;
module_param(gpio_fail_offset, int, 0644);
static int gpio_fail_op;
module_param(gpio_fail_op, int, 0644);
static int gpio_fail_count;
module_param(gpio_fail_count, int, 0644);
static int gpio_fail_skip;
module_param(gpio_fail_skip, int, 0644);

/* True (and one fewer left) when this request is to fail. */
static bool ccb_take_fault(int *count, bool match)
{
	unsigned long flags;
	bool take = false;

	spin_lock_irqsave(&ccb_fault_lock, flags);
	if (match && *count > 0) {
		--*count;
		take = true;
	}
	spin_unlock_irqrestore(&ccb_fault_lock, flags);
	return take;
}

/* ---- the request slot and the character device ---- */

static DEFINE_MUTEX(ccb_xfer_lock);  /* one request in flight */
static DEFINE_MUTEX(ccb_state_lock); /* the fields below */
static DECLARE_WAIT_QUEUE_HEAD(ccb_readq);
static bool ccb_server;     /* /dev/caracara-bridge is open */
static bool ccb_active;     /* a request awaits its reply */
static bool ccb_unread;     /* ... and user space has not read it yet */
static u32 ccb_seq;
static void *ccb_req;
static size_t ccb_req_len;
static void *ccb_reply;     /* where the reply's payload goes */
static size_t ccb_reply_cap;
static size_t ccb_reply_len;
static int ccb_result;
static DECLARE_COMPLETION(ccb_done);

/* Sends the request in `req` (header filled in here except len) and waits for the reply.
 * Returns the reply's result or -errno; *reply_len gets the payload length. */
static int ccb_transact(void *req, size_t len, u16 type, u16 arg, void *reply, size_t reply_cap,
			size_t *reply_len)
{
	struct ccb_header *h = req;
	unsigned long left;
	int ret;

	mutex_lock(&ccb_xfer_lock);
	mutex_lock(&ccb_state_lock);
	if (!ccb_server) {
		mutex_unlock(&ccb_state_lock);
		mutex_unlock(&ccb_xfer_lock);
		return -ENXIO;
	}
	h->len = len;
	h->seq = ++ccb_seq ? ccb_seq : ++ccb_seq;
	h->type = type;
	h->arg = arg;
	h->result = 0;
	ccb_req = req;
	ccb_req_len = len;
	ccb_reply = reply;
	ccb_reply_cap = reply_cap;
	ccb_reply_len = 0;
	ccb_result = -EIO;
	reinit_completion(&ccb_done);
	ccb_active = true;
	ccb_unread = true;
	mutex_unlock(&ccb_state_lock);
	wake_up_interruptible(&ccb_readq);

	left = wait_for_completion_timeout(&ccb_done, msecs_to_jiffies(timeout_ms));

	mutex_lock(&ccb_state_lock);
	if (ccb_active) { /* timed out: nobody may touch req or reply any more */
		ccb_active = false;
		ccb_unread = false;
		ret = -ETIMEDOUT;
	} else {
		ret = ccb_result;
	}
	if (reply_len)
		*reply_len = ccb_reply_len;
	ccb_req = NULL;
	ccb_reply = NULL;
	mutex_unlock(&ccb_state_lock);
	mutex_unlock(&ccb_xfer_lock);
	(void)left;
	return ret;
}

static int ccb_open(struct inode *inode, struct file *f)
{
	int ret = 0;

	mutex_lock(&ccb_state_lock);
	if (ccb_server)
		ret = -EBUSY;
	else
		ccb_server = true;
	mutex_unlock(&ccb_state_lock);
	return ret;
}

static int ccb_release(struct inode *inode, struct file *f)
{
	mutex_lock(&ccb_state_lock);
	ccb_server = false;
	if (ccb_active) {
		ccb_active = false;
		ccb_unread = false;
		ccb_result = -ENXIO;
		complete(&ccb_done);
	}
	mutex_unlock(&ccb_state_lock);
	return 0;
}

static ssize_t ccb_read(struct file *f, char __user *buf, size_t count, loff_t *ppos)
{
	ssize_t ret;

	for (;;) {
		mutex_lock(&ccb_state_lock);
		if (ccb_unread)
			break;
		mutex_unlock(&ccb_state_lock);
		if (f->f_flags & O_NONBLOCK)
			return -EAGAIN;
		if (wait_event_interruptible(ccb_readq, READ_ONCE(ccb_unread)))
			return -ERESTARTSYS;
	}
	if (count < ccb_req_len) {
		ret = -EMSGSIZE;
	} else if (copy_to_user(buf, ccb_req, ccb_req_len)) {
		ret = -EFAULT;
	} else {
		ccb_unread = false;
		ret = ccb_req_len;
	}
	mutex_unlock(&ccb_state_lock);
	return ret;
}

static __poll_t ccb_poll(struct file *f, poll_table *wait)
{
	poll_wait(f, &ccb_readq, wait);
	return READ_ONCE(ccb_unread) ? EPOLLIN | EPOLLRDNORM : 0;
}

static void ccb_gpio_level(u32 offset, u32 value);

static ssize_t ccb_write(struct file *f, const char __user *buf, size_t count, loff_t *ppos)
{
	struct ccb_header *h;
	void *msg;
	ssize_t ret = count;

	if (count < sizeof(*h) || count > CCB_MAX_MESSAGE)
		return -EINVAL;
	msg = kvmalloc(count, GFP_KERNEL);
	if (!msg)
		return -ENOMEM;
	if (copy_from_user(msg, buf, count)) {
		kvfree(msg);
		return -EFAULT;
	}
	h = msg;
	if (h->len != count) {
		ret = -EINVAL;
	} else if (h->type == CCB_GPIO_LEVEL) {
		struct ccb_gpio *g = (struct ccb_gpio *)(h + 1);

		if (count < sizeof(*h) + sizeof(*g) || g->offset >= CCB_NGPIO)
			ret = -EINVAL;
		else
			ccb_gpio_level(g->offset, g->value);
	} else if (h->type & CCB_REPLY) {
		size_t n = count - sizeof(*h);

		mutex_lock(&ccb_state_lock);
		if (!ccb_active || ccb_unread || h->seq != ccb_seq ||
		    (h->type & ~CCB_REPLY) != ((struct ccb_header *)ccb_req)->type) {
			ret = -ESRCH; /* late (timed out) or not the request in flight */
		} else if (n > ccb_reply_cap) {
			ccb_result = -EPROTO;
			ccb_active = false;
			complete(&ccb_done);
		} else {
			if (n)
				memcpy(ccb_reply, h + 1, n);
			ccb_reply_len = n;
			ccb_result = h->result;
			ccb_active = false;
			complete(&ccb_done);
		}
		mutex_unlock(&ccb_state_lock);
	} else {
		ret = -EINVAL;
	}
	kvfree(msg);
	return ret;
}

static const struct file_operations ccb_fops = {
	.owner = THIS_MODULE,
	.open = ccb_open,
	.release = ccb_release,
	.read = ccb_read,
	.write = ccb_write,
	.poll = ccb_poll,
	.llseek = noop_llseek,
};

static struct miscdevice ccb_misc = {
	.minor = MISC_DYNAMIC_MINOR,
	.name = CCB_DEVICE_NAME,
	.fops = &ccb_fops,
	.mode = 0600,
};

/* ---- I2C adapter on a platform device ---- */

static int ccb_i2c_xfer(struct i2c_adapter *adap, struct i2c_msg *msgs, int num)
{
	size_t len = sizeof(struct ccb_header) + sizeof(u32), rlen = 0, got = 0, off;
	void *req, *reply;
	u8 *p;
	int i, ret, fail_addr = READ_ONCE(i2c_fail_addr);

	if (ccb_take_fault(&i2c_fail_count, fail_addr < 0 || (num > 0 && msgs[0].addr == fail_addr)))
		return i2c_fail_errno ? -abs(i2c_fail_errno) : num - 1;
	for (i = 0; i < num; i++) {
		len += sizeof(struct ccb_i2c_msg);
		if (msgs[i].flags & I2C_M_RD)
			rlen += msgs[i].len;
		else
			len += msgs[i].len;
	}
	if (len > CCB_MAX_MESSAGE || rlen > CCB_MAX_MESSAGE)
		return -EINVAL;
	req = kvzalloc(len, GFP_KERNEL);
	reply = kvzalloc(rlen ? rlen : 1, GFP_KERNEL);
	if (!req || !reply) {
		ret = -ENOMEM;
		goto out;
	}
	p = (u8 *)req + sizeof(struct ccb_header);
	*(u32 *)p = num;
	p += sizeof(u32);
	for (i = 0; i < num; i++) {
		struct ccb_i2c_msg m = { .addr = msgs[i].addr, .flags = msgs[i].flags, .len = msgs[i].len };

		memcpy(p, &m, sizeof(m));
		p += sizeof(m);
		if (!(msgs[i].flags & I2C_M_RD)) {
			memcpy(p, msgs[i].buf, msgs[i].len);
			p += msgs[i].len;
		}
	}
	ret = ccb_transact(req, len, CCB_I2C_XFER, 0, reply, rlen, &got);
	if (ret >= 0) {
		if (got != rlen) {
			ret = -EPROTO;
			goto out;
		}
		off = 0;
		for (i = 0; i < num; i++) {
			if (msgs[i].flags & I2C_M_RD) {
				memcpy(msgs[i].buf, (u8 *)reply + off, msgs[i].len);
				off += msgs[i].len;
			}
		}
		if (ret > num)
			ret = num;
	}
out:
	kvfree(req);
	kvfree(reply);
	return ret;
}

static u32 ccb_i2c_func(struct i2c_adapter *adap)
{
	if (ccb_take_fault(&i2c_func_fail_count, true))
		return I2C_FUNC_SMBUS_EMUL;
	return I2C_FUNC_I2C | I2C_FUNC_SMBUS_EMUL;
}

static const struct i2c_algorithm ccb_i2c_algo = {
	.master_xfer = ccb_i2c_xfer,
	.functionality = ccb_i2c_func,
};

static void ccb_notify_bind(bool bound)
{
	struct ccb_header h;

	/* At module load no server is attached yet: -ENXIO, nothing to tell. */
	ccb_transact(&h, sizeof(h), CCB_I2C_BIND, bound, NULL, 0, NULL);
}

static int ccb_i2c_probe(struct platform_device *pdev)
{
	struct i2c_adapter *adap;
	int ret;

	if (ccb_take_fault(&i2c_probe_fail_count, true))
		return -abs(i2c_probe_errno);
	adap = devm_kzalloc(&pdev->dev, sizeof(*adap), GFP_KERNEL);
	if (!adap)
		return -ENOMEM;
	adap->owner = THIS_MODULE;
	adap->class = I2C_CLASS_DEPRECATED;
	adap->algo = &ccb_i2c_algo;
	adap->dev.parent = &pdev->dev;
	adap->nr = i2c_bus;
	adap->timeout = msecs_to_jiffies(1000);
	strscpy(adap->name, "caracara-bridge I2C adapter", sizeof(adap->name));
	ret = i2c_add_numbered_adapter(adap);
	if (ret)
		return ret;
	platform_set_drvdata(pdev, adap);
	ccb_notify_bind(true);
	return 0;
}

static CCB_REMOVE_RET ccb_i2c_remove(struct platform_device *pdev)
{
	i2c_del_adapter(platform_get_drvdata(pdev));
	ccb_notify_bind(false);
	return CCB_REMOVE_OK;
}

static struct platform_driver ccb_i2c_driver = {
	.probe = ccb_i2c_probe,
	.remove = ccb_i2c_remove,
	.driver = { .name = "caracara-i2c" },
};

/* ---- SPI controller with a spidev device ---- */

static int ccb_spi_transfer_one_message(struct spi_controller *ctlr, struct spi_message *m)
{
	struct spi_device *spi = m->spi;
	struct spi_transfer *t;
	size_t len = sizeof(struct ccb_header) + sizeof(struct ccb_spi_msg), rlen = 0, got = 0, off;
	struct ccb_spi_msg sm = {};
	void *req, *reply = NULL;
	u8 *p;
	int ret;

	if (ccb_take_fault(&spi_fail_count, true)) {
		ret = -abs(spi_fail_errno);
		goto done;
	}
	if (ccb_take_fault(&spi_silent_count, true)) {
		/* A silent slave: the controller clocks the message, MISO reads low. */
		list_for_each_entry(t, &m->transfers, transfer_list) {
			if (t->rx_buf)
				memset(t->rx_buf, 0, t->len);
			m->actual_length += t->len;
		}
		ret = 0;
		goto done;
	}
	list_for_each_entry(t, &m->transfers, transfer_list) {
		len += sizeof(struct ccb_spi_xfer) + (t->tx_buf ? t->len : 0);
		rlen += t->rx_buf ? t->len : 0;
		sm.count++;
	}
	if (len > CCB_MAX_MESSAGE || rlen > CCB_MAX_MESSAGE) {
		ret = -EINVAL;
		goto done;
	}
	req = kvzalloc(len, GFP_KERNEL);
	reply = kvzalloc(rlen ? rlen : 1, GFP_KERNEL);
	if (!req || !reply) {
		kvfree(req);
		ret = -ENOMEM;
		goto done;
	}
	sm.mode = spi->mode;
	sm.max_speed_hz = spi->max_speed_hz;
	sm.chip_select = ccb_chip_select(spi);
	sm.bits_per_word = spi->bits_per_word;
	p = (u8 *)req + sizeof(struct ccb_header);
	memcpy(p, &sm, sizeof(sm));
	p += sizeof(sm);
	list_for_each_entry(t, &m->transfers, transfer_list) {
		struct ccb_spi_xfer x = {
			.len = t->len,
			.speed_hz = t->speed_hz,
			.bits_per_word = t->bits_per_word,
			.cs_change = t->cs_change,
			.has_tx = !!t->tx_buf,
			.want_rx = !!t->rx_buf,
		};

		if (t->delay.unit == SPI_DELAY_UNIT_USECS)
			x.delay_usecs = t->delay.value;
		else if (t->delay.unit == SPI_DELAY_UNIT_NSECS)
			x.delay_usecs = DIV_ROUND_UP(t->delay.value, 1000);
		memcpy(p, &x, sizeof(x));
		p += sizeof(x);
		if (t->tx_buf) {
			memcpy(p, t->tx_buf, t->len);
			p += t->len;
		}
	}
	ret = ccb_transact(req, len, CCB_SPI_MSG, 0, reply, rlen, &got);
	kvfree(req);
	if (ret >= 0) {
		if (got != rlen) {
			ret = -EPROTO;
			goto done;
		}
		off = 0;
		list_for_each_entry(t, &m->transfers, transfer_list) {
			if (t->rx_buf) {
				memcpy(t->rx_buf, (u8 *)reply + off, t->len);
				off += t->len;
			}
		}
		m->actual_length = ret;
		ret = 0;
	}
done:
	kvfree(reply);
	m->status = ret;
	spi_finalize_current_message(ctlr);
	return ret;
}

static bool ccb_spi_probing; /* the controller's own device being added: never failed */

static int ccb_spi_setup(struct spi_device *spi)
{
	if (!READ_ONCE(ccb_spi_probing) && ccb_take_fault(&spi_setup_fail_count, true))
		return -EINVAL;
	return 0;
}

static struct spi_controller *ccb_spi_ctlr;
static struct spi_device *ccb_spidev;

static int ccb_spi_probe(struct platform_device *pdev)
{
	struct spi_controller *ctlr;
	struct spi_device *spi;
	int ret;

	ctlr = spi_alloc_master(&pdev->dev, 0);
	if (!ctlr)
		return -ENOMEM;
	ctlr->bus_num = spi_bus;
	ctlr->num_chipselect = 1;
	ctlr->mode_bits = SPI_CPHA | SPI_CPOL | SPI_CS_HIGH | SPI_LSB_FIRST;
	ctlr->bits_per_word_mask = SPI_BPW_RANGE_MASK(1, 32);
	ctlr->max_speed_hz = 50000000;
	ctlr->min_speed_hz = 1000;
	ctlr->setup = ccb_spi_setup;
	ctlr->transfer_one_message = ccb_spi_transfer_one_message;
	ret = spi_register_controller(ctlr);
	if (ret) {
		spi_controller_put(ctlr);
		return ret;
	}
	spi = spi_alloc_device(ctlr);
	if (!spi) {
		spi_unregister_controller(ctlr);
		return -ENOMEM;
	}
	ccb_set_chip_select(spi, 0);
	spi->max_speed_hz = 500000;
	spi->mode = SPI_MODE_0;
	spi->bits_per_word = 8;
	strscpy(spi->modalias, "spidev", sizeof(spi->modalias));
	/* spidev refuses to be named by a board; driver_override binds it. */
#ifdef CCB_DEVICE_DRIVER_OVERRIDE
	ret = device_set_driver_override(&spi->dev, "spidev");
	if (ret) {
		spi_dev_put(spi);
		spi_unregister_controller(ctlr);
		return ret;
	}
#else
	spi->driver_override = kstrdup("spidev", GFP_KERNEL);
#endif
	WRITE_ONCE(ccb_spi_probing, true);
	ret = spi_add_device(spi);
	WRITE_ONCE(ccb_spi_probing, false);
	if (ret) {
		spi_dev_put(spi);
		spi_unregister_controller(ctlr);
		return ret;
	}
	ccb_spi_ctlr = ctlr;
	ccb_spidev = spi;
	return 0;
}

static CCB_REMOVE_RET ccb_spi_remove(struct platform_device *pdev)
{
	spi_unregister_device(ccb_spidev);
	spi_unregister_controller(ccb_spi_ctlr);
	return CCB_REMOVE_OK;
}

static struct platform_driver ccb_spi_driver = {
	.probe = ccb_spi_probe,
	.remove = ccb_spi_remove,
	.driver = { .name = "caracara-spi" },
};

/* ---- GPIO chip with edge interrupts ---- */

static struct gpio_chip ccb_gc;
static DEFINE_SPINLOCK(ccb_gpio_lock);
static u8 ccb_level[CCB_NGPIO];   /* last level user space reported */
static struct task_struct *ccb_level_task; /* the server, inside its level write */
static u8 ccb_out[CCB_NGPIO];     /* 1 = output (for get_direction) */
static u8 ccb_od[CCB_NGPIO];      /* open drain configured */
static u8 ccb_irq_on[CCB_NGPIO];  /* unmasked */
static u8 ccb_irq_used[CCB_NGPIO];/* requested as an interrupt */
static unsigned int ccb_irq_type[CCB_NGPIO];
static const char *const ccb_names[CCB_NGPIO] = {
	"GPIO0", "GPIO1", "GPIO2", "GPIO3", "GPIO4", "GPIO5", "GPIO6", "GPIO7", "GPIO8", "GPIO9",
	"GPIO10", "GPIO11", "GPIO12", "GPIO13", "GPIO14", "GPIO15", "GPIO16", "GPIO17", "GPIO18",
	"GPIO19", "GPIO20", "GPIO21", "GPIO22", "GPIO23", "GPIO24", "GPIO25", "GPIO26", "GPIO27",
};

/* The injected result of this line operation: -errno, or 0 (a GET reads low) when it is to
 * fail; 1 when it goes on as usual. */
static int ccb_gpio_fault(unsigned int offset, u16 op)
{
	int fop = READ_ONCE(gpio_fail_op), foff = READ_ONCE(gpio_fail_offset);
	unsigned long flags;
	bool take = false;

	if ((fop && fop != op) || (foff >= 0 && foff != offset))
		return 1;
	spin_lock_irqsave(&ccb_fault_lock, flags);
	if (gpio_fail_count > 0) {
		if (gpio_fail_skip > 0) {
			gpio_fail_skip--;
		} else {
			gpio_fail_count--;
			take = true;
		}
	}
	spin_unlock_irqrestore(&ccb_fault_lock, flags);
	if (!take)
		return 1;
	return gpio_fail_errno ? -abs(gpio_fail_errno) : 0;
}

static int ccb_gpio_op(unsigned int offset, u16 op, u32 value, u32 flags)
{
	struct {
		struct ccb_header h;
		struct ccb_gpio g;
	} req = { .g = { .offset = offset, .value = value, .flags = flags } };
	int fault = ccb_gpio_fault(offset, op);

	if (fault <= 0)
		return fault;
	return ccb_transact(&req, sizeof(req), CCB_GPIO, op, NULL, 0, NULL);
}

static int ccb_gpio_request(struct gpio_chip *gc, unsigned int offset)
{
	return ccb_gpio_op(offset, CCB_GPIO_REQUEST, 0, 0);
}

static void ccb_gpio_free(struct gpio_chip *gc, unsigned int offset)
{
	ccb_od[offset] = 0;
	ccb_gpio_op(offset, CCB_GPIO_FREE, 0, 0);
}

static int ccb_gpio_get_direction(struct gpio_chip *gc, unsigned int offset)
{
	return ccb_out[offset] ? GPIO_LINE_DIRECTION_OUT : GPIO_LINE_DIRECTION_IN;
}

static int ccb_gpio_direction_input(struct gpio_chip *gc, unsigned int offset)
{
	int ret = ccb_gpio_op(offset, CCB_GPIO_INPUT, 0, 0);

	if (!ret)
		ccb_out[offset] = 0;
	return ret;
}

static int ccb_gpio_direction_output(struct gpio_chip *gc, unsigned int offset, int value)
{
	int ret = ccb_gpio_op(offset, CCB_GPIO_OUTPUT, !!value, ccb_od[offset] ? CCB_GPIO_OPEN_DRAIN : 0);

	if (!ret)
		ccb_out[offset] = 1;
	return ret;
}

static int ccb_gpio_get(struct gpio_chip *gc, unsigned int offset)
{
	unsigned long flags;
	int v = -1;

	/* A line in use as an interrupt is read by its handler while the server is still
	 * inside the write() that reported the edge: answer from the reported level. */
	spin_lock_irqsave(&ccb_gpio_lock, flags);
	if (ccb_irq_used[offset])
		v = ccb_level[offset];
	spin_unlock_irqrestore(&ccb_gpio_lock, flags);
	if (v >= 0) {
		/* The edge handler (inside the server's write) reads too: only a reader's get fails. */
		if (READ_ONCE(ccb_level_task) != current) {
			int fault = ccb_gpio_fault(offset, CCB_GPIO_GET);

			if (fault <= 0)
				return fault;
		}
		return v;
	}
	return ccb_gpio_op(offset, CCB_GPIO_GET, 0, 0);
}

static void ccb_gpio_set(struct gpio_chip *gc, unsigned int offset, int value)
{
	ccb_gpio_op(offset, CCB_GPIO_SET, !!value, 0);
}

static int ccb_gpio_set_config(struct gpio_chip *gc, unsigned int offset, unsigned long config)
{
	switch (pinconf_to_config_param(config)) {
	case PIN_CONFIG_DRIVE_OPEN_DRAIN:
		ccb_od[offset] = 1;
		return 0;
	case PIN_CONFIG_DRIVE_PUSH_PULL:
		ccb_od[offset] = 0;
		return 0;
	default:
		return -ENOTSUPP;
	}
}

static void ccb_gpio_level(u32 offset, u32 value)
{
	unsigned long flags;
	unsigned int type;
	bool fire = false;
	u8 old;

	value = !!value;
	spin_lock_irqsave(&ccb_gpio_lock, flags);
	old = ccb_level[offset];
	ccb_level[offset] = value;
	type = ccb_irq_type[offset];
	if (ccb_irq_on[offset] && old != value)
		fire = value ? (type & IRQ_TYPE_EDGE_RISING) : (type & IRQ_TYPE_EDGE_FALLING);
	spin_unlock_irqrestore(&ccb_gpio_lock, flags);
	if (fire) {
		unsigned int irq = irq_find_mapping(ccb_gc.irq.domain, offset);

		if (irq) {
			WRITE_ONCE(ccb_level_task, current);
			handle_nested_irq(irq);
			WRITE_ONCE(ccb_level_task, NULL);
		}
	}
}

static void ccb_irq_mask(struct irq_data *d)
{
	irq_hw_number_t hw = irqd_to_hwirq(d);

	ccb_irq_on[hw] = 0;
	gpiochip_disable_irq(&ccb_gc, hw);
}

static void ccb_irq_unmask(struct irq_data *d)
{
	irq_hw_number_t hw = irqd_to_hwirq(d);

	gpiochip_enable_irq(&ccb_gc, hw);
	ccb_irq_on[hw] = 1;
}

static int ccb_irq_set_type(struct irq_data *d, unsigned int type)
{
	irq_hw_number_t hw = irqd_to_hwirq(d);

	if (type & (IRQ_TYPE_LEVEL_HIGH | IRQ_TYPE_LEVEL_LOW))
		return -EINVAL;
	ccb_irq_type[hw] = type;
	return 0;
}

static int ccb_irq_reqres(struct irq_data *d)
{
	irq_hw_number_t hw = irqd_to_hwirq(d);
	int ret = gpiochip_reqres_irq(&ccb_gc, hw);

	if (!ret)
		ccb_irq_used[hw] = 1;
	return ret;
}

static void ccb_irq_relres(struct irq_data *d)
{
	irq_hw_number_t hw = irqd_to_hwirq(d);

	ccb_irq_used[hw] = 0;
	gpiochip_relres_irq(&ccb_gc, hw);
}

static const struct irq_chip ccb_irq_chip = {
	.name = "caracara-gpio",
	.irq_mask = ccb_irq_mask,
	.irq_unmask = ccb_irq_unmask,
	.irq_set_type = ccb_irq_set_type,
	.irq_request_resources = ccb_irq_reqres,
	.irq_release_resources = ccb_irq_relres,
	.flags = IRQCHIP_IMMUTABLE | IRQCHIP_SKIP_SET_WAKE,
};

static int ccb_gpio_probe(struct platform_device *pdev)
{
	struct gpio_irq_chip *girq;

	/* Unbind and bind again (a chip that goes while its lines are held): a clean chip. */
	memset(&ccb_gc, 0, sizeof(ccb_gc));
	memset(ccb_irq_on, 0, sizeof(ccb_irq_on));
	memset(ccb_irq_used, 0, sizeof(ccb_irq_used));
	ccb_gc.label = "caracara-gpio";
	ccb_gc.parent = &pdev->dev;
	ccb_gc.owner = THIS_MODULE;
	ccb_gc.base = -1;
	ccb_gc.ngpio = CCB_NGPIO;
	/* The line names come from the device's "gpio-line-names" property, not gc.names: with
	 * gc.names, Linux 6.1 looks every name up in all chips, and a chip removed while its lines
	 * were held stays in that list without its gpio_chip (a NULL dereference at the next add). */
	ccb_gc.can_sleep = true;
	ccb_gc.request = ccb_gpio_request;
	ccb_gc.free = ccb_gpio_free;
	ccb_gc.get_direction = ccb_gpio_get_direction;
	ccb_gc.direction_input = ccb_gpio_direction_input;
	ccb_gc.direction_output = ccb_gpio_direction_output;
	ccb_gc.get = ccb_gpio_get;
	ccb_gc.set = ccb_gpio_set;
	ccb_gc.set_config = ccb_gpio_set_config;
	girq = &ccb_gc.irq;
	gpio_irq_chip_set_chip(girq, &ccb_irq_chip);
	girq->handler = handle_simple_irq;
	girq->default_type = IRQ_TYPE_NONE;
	girq->threaded = true;
	return devm_gpiochip_add_data(&pdev->dev, &ccb_gc, NULL);
}

static struct platform_driver ccb_gpio_driver = {
	.probe = ccb_gpio_probe,
	.driver = { .name = "caracara-gpio" },
};

/* ---- module ---- */

static const struct property_entry ccb_gpio_props[] = {
	PROPERTY_ENTRY_STRING_ARRAY("gpio-line-names", ccb_names),
	{}
};

static const struct platform_device_info ccb_gpio_info = {
	.name = "caracara-gpio",
	.id = PLATFORM_DEVID_NONE,
	.properties = ccb_gpio_props,
};

static struct platform_device *ccb_i2c_pdev, *ccb_spi_pdev, *ccb_gpio_pdev;

static void ccb_cleanup(void)
{
	if (ccb_gpio_pdev)
		platform_device_unregister(ccb_gpio_pdev);
	if (ccb_spi_pdev)
		platform_device_unregister(ccb_spi_pdev);
	if (ccb_i2c_pdev)
		platform_device_unregister(ccb_i2c_pdev);
	platform_driver_unregister(&ccb_gpio_driver);
	platform_driver_unregister(&ccb_spi_driver);
	platform_driver_unregister(&ccb_i2c_driver);
	misc_deregister(&ccb_misc);
}

static int __init ccb_init(void)
{
	int ret;

	ret = misc_register(&ccb_misc);
	if (ret)
		return ret;
	ret = platform_driver_register(&ccb_i2c_driver);
	if (!ret)
		ret = platform_driver_register(&ccb_spi_driver);
	if (!ret)
		ret = platform_driver_register(&ccb_gpio_driver);
	if (ret)
		goto fail;
	ccb_i2c_pdev = platform_device_register_simple("caracara-i2c", PLATFORM_DEVID_NONE, NULL, 0);
	ccb_spi_pdev = platform_device_register_simple("caracara-spi", PLATFORM_DEVID_NONE, NULL, 0);
	ccb_gpio_pdev = platform_device_register_full(&ccb_gpio_info);
	if (IS_ERR(ccb_i2c_pdev) || IS_ERR(ccb_spi_pdev) || IS_ERR(ccb_gpio_pdev)) {
		ret = -ENODEV;
		if (IS_ERR(ccb_i2c_pdev))
			ccb_i2c_pdev = NULL;
		if (IS_ERR(ccb_spi_pdev))
			ccb_spi_pdev = NULL;
		if (IS_ERR(ccb_gpio_pdev))
			ccb_gpio_pdev = NULL;
		goto fail;
	}
	return 0;
fail:
	ccb_cleanup();
	return ret;
}

static void __exit ccb_exit(void)
{
	ccb_cleanup();
}

module_init(ccb_init);
module_exit(ccb_exit);
MODULE_DESCRIPTION("caracara test bridge: I2C adapter, SPI controller and GPIO chip served from user space");
MODULE_LICENSE("GPL");
