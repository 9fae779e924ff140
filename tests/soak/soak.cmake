# The fault soak (tests/soak/soak.py): caracarad against caracara-sim under a 50 Hz command
# stream with client churn and random faults, the books checked from the wire log. A short run
# here (60 s); scripts/soak.sh runs the long one. Normal build only (the sanitizer build runs
# the same code in the e2e and integration tests).
if(NOT CARACARA_SANITIZE)
  add_test(NAME soak_short
           COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/soak.py --seconds 60 --seed 1)
  set_tests_properties(soak_short PROPERTIES
                       ENVIRONMENT "CARACARA_BUILD_DIR=${CMAKE_BINARY_DIR};PYTHONDONTWRITEBYTECODE=1;${CARACARA_TEST_ENV}"
                       TIMEOUT 300
                       LABELS soak)
endif()
