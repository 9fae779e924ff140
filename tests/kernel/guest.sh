#!/bin/bash
# Runs inside the VM, chrooted into the host root (tests/kernel/guest-init.sh): loads the
# bridge module, then the scenarios; results go to $OUT (shared with the host).
set -u
export PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin
echo "guest: $(uname -r), $(nproc) CPU, $(. /etc/os-release && echo "$PRETTY_NAME")"
[ -n "${TOP:-}" ] || { echo "guest: no environment"; exit 1; }
if ! /sbin/insmod "$WORK/module/caracara_bridge.ko"; then
  echo "FAIL module: insmod" > "$OUT/results.txt"; exit 1
fi
ls -l /dev/caracara-bridge /dev/i2c-* /dev/spidev* /dev/gpiochip* 2>&1
export TMPDIR=/run/tmp HOME=/run/tmp
export GCOV_PREFIX="$OUT/gcov" GCOV_PREFIX_STRIP=0
# A caracarad that dies of its fatal signal writes its counters too (tests/kernel/gcov_flush.c).
export LD_PRELOAD="$WORK/gcov_flush.so"
export CARACARA_BUILD_DIR="$COV" PYTHONDONTWRITEBYTECODE=1
cd "$TOP/tests/kernel"
timeout 600 /usr/bin/python3 scenarios.py "$OUT/results.txt" ${SCENARIOS:-}
echo "guest: scenarios exited $?"
