# The system test (tests/system/run.sh): caracarad under a real systemd and system bus in a
# Debian 12 container booted with systemd-nspawn, with the files `cmake --install` puts in
# place. Needs root; exit status 77 (skipped) otherwise. Run once, in the normal build.
if(NOT CARACARA_SANITIZE AND NOT CMAKE_CROSSCOMPILING)
  add_test(NAME system_nspawn COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/system/run.sh ${CMAKE_BINARY_DIR})
  set_tests_properties(system_nspawn PROPERTIES TIMEOUT 1200 LABELS system SKIP_RETURN_CODE 77)
endif()
