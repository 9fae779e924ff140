# The kernel test (issue #14): Debian's kernel under QEMU with the test module
# tests/kernel/module/caracara_bridge.c, caracara-sim --kernel-bridge and caracarad on the
# kernel's own /dev/i2c-1, /dev/spidev0.0 and /dev/gpiochip0 (tests/kernel/run.sh).
# Needs root (apt-get download into /var/cache/caracara-kernel, QEMU and i2c-tools packages);
# exit 77 = skipped when it cannot run (not root, no QEMU) outside CI; under CI (CI=true) that
# fails. Only in the normal build: the sanitizer build would boot the same kernel again for nothing (the daemon in the VM is a --coverage build of its own).
# Not in a cross build: the guest is amd64. Run alone with `ctest -L kernel`.
if(NOT CARACARA_SANITIZE AND NOT CMAKE_CROSSCOMPILING)
  add_test(NAME kernel COMMAND ${CMAKE_CURRENT_LIST_DIR}/run.sh ${CMAKE_BINARY_DIR}/kernel)
  set_tests_properties(kernel PROPERTIES LABELS kernel TIMEOUT 1500 SKIP_RETURN_CODE 77)
endif()

# The doc check run.sh ends with (tests/kernel/write_doc.py --check), on a section and run outputs
# made by the test itself: no QEMU, no root; in every build (the Debian 13 root's ctest too).
add_test(NAME kernel_doc_check COMMAND /usr/bin/python3 -m unittest -v test_write_doc
         WORKING_DIRECTORY ${CMAKE_CURRENT_LIST_DIR})
set_tests_properties(kernel_doc_check PROPERTIES ENVIRONMENT "PYTHONDONTWRITEBYTECODE=1")
