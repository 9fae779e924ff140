# caracara-bridge with the Foxglove reference client and the MCAP reference reader (npm packages
# pinned in tests/bridge/package-lock.json, cached under /var/cache/caracara-npm), through a
# real ssh -L forward to a private sshd (tests/bridge/test_bridge.py).
caracara_python_test(e2e_bridge test_bridge ${CMAKE_CURRENT_LIST_DIR} LABELS e2e bridge)

# The cockpit in Debian's chromium (headless, puppeteer-core) through the same kind of forward.
caracara_python_test(e2e_cockpit test_cockpit ${CMAKE_CURRENT_LIST_DIR} LABELS e2e bridge cockpit)
