# The control loop's pure policies (order schedule, lockup detector, recovery policy).
caracara_unit_test(test_policies SOURCES unit/test_policies.cpp LIBS caracara_core)
