# The system test (tests/system/run.sh): caracarad under a real systemd and system bus in a
# Debian 12 container booted with systemd-nspawn, installed from this tree's Debian packages
# with apt-get (then upgraded while the thrusters run, and purged). system_debs builds them
# first (scripts/package.sh, nocheck: the suite runs here anyway; alone, so that its compile
# does not slow the timing-sensitive tests down). Needs root; exit status 77 (skipped) otherwise,
# a failure under CI (CI=true).
# Run once, in the normal build.
if(NOT CARACARA_SANITIZE AND NOT CMAKE_CROSSCOMPILING)
  add_test(NAME system_debs
           COMMAND ${CMAKE_COMMAND} -E env DEB_BUILD_OPTIONS=nocheck
                   ${CMAKE_SOURCE_DIR}/scripts/package.sh native ${CMAKE_BINARY_DIR}/debs)
  set_tests_properties(system_debs PROPERTIES TIMEOUT 900 LABELS system RUN_SERIAL TRUE
                       FIXTURES_SETUP caracara_debs)
  add_test(NAME system_nspawn COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/system/run.sh --debs ${CMAKE_BINARY_DIR}/debs)
  set_tests_properties(system_nspawn PROPERTIES TIMEOUT 1200 LABELS system SKIP_RETURN_CODE 77
                       FIXTURES_REQUIRED caracara_debs)
endif()
# The Debian 13 test (tests/system/debian13.sh): this source tree built with warnings as errors
# and tested (ctest) in a cached Debian 13 root, its Debian packages built there, then the checks
# above in a booted Debian 13 container that installs them, and the kernel test with that build.
# Root only (77 otherwise, or with CARACARA_SKIP_DEBIAN13=1). Not alone: beside the other tests,
# since most of its time is its own ctest, container and VM waiting on the vehicle's clock; it
# takes two of ctest's slots (scripts/test.sh runs twice the cores: a slot is half a core) for its
# compiles, and starts first (its COST, tests/CMakeLists.txt). Only it: given two slots too, the
# kernel test's QEMU and the cockpit's Chromium waited for two free ones until every shorter test
# had run (they started 13 and 18 minutes into the step, 2026-12-05). amd64 only, like the tests
# above: not in a cross build.
if(NOT CARACARA_SANITIZE AND NOT CMAKE_CROSSCOMPILING)
  add_test(NAME system_debian13 COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/system/debian13.sh ${CMAKE_SOURCE_DIR})
  set_tests_properties(system_debian13 PROPERTIES TIMEOUT 2400 LABELS "system;debian13"
                       SKIP_RETURN_CODE 77 PROCESSORS 2)
endif()
