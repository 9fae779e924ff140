#!/bin/sh
# /init of the kernel test's initramfs (tests/kernel/run.sh): mounts the host root shared
# over 9p, loads the test module and runs tests/kernel/guest.sh chrooted into the host root.
export PATH=/bin
busybox mount -t proc proc /proc
busybox mount -t sysfs sys /sys
busybox mount -t devtmpfs dev /dev
set -a; . /env; set +a
for m in $(busybox cat /modules); do
  busybox insmod "/lib/modules/$m" || echo "init: insmod $m failed"
done
n=/newroot
busybox mount -t 9p -o trans=virtio,version=9p2000.L,msize=262144,cache=loose,ro hostroot $n || {
  echo "init: cannot mount the host root"; busybox poweroff -f; }
busybox mount -t 9p -o trans=virtio,version=9p2000.L,msize=262144 results "$n$OUT"
busybox mount -t proc proc $n/proc
busybox mount -t sysfs sys $n/sys
busybox mount -t devtmpfs dev $n/dev
busybox mkdir -p $n/dev/shm 2>/dev/null
busybox mount -t tmpfs shm $n/dev/shm
busybox mount -t tmpfs run $n/run
busybox mount -t tmpfs tmp $n/var/tmp
busybox mount -t debugfs debugfs $n/sys/kernel/debug 2>/dev/null
busybox chroot $n /bin/bash "$TOP/tests/kernel/guest.sh" > "$n$OUT/guest.log" 2>&1
busybox dmesg > "$n$OUT/dmesg.txt"
busybox sync
busybox poweroff -f
