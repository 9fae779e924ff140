# The control loop's pure policies (order schedule, lockup detector, recovery policy).
caracara_unit_test(test_policies SOURCES unit/test_policies.cpp unit/test_motor_demand.cpp LIBS caracara_core)
