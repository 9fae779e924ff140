# The control loop's pure policies (order schedule, lockup detector, recovery policy).
caracara_unit_test(test_policies SOURCES unit/test_policies.cpp unit/test_motor_demand.cpp LIBS caracara_core)
# The dive file format and the [recorder] section.
caracara_unit_test(test_dive_format SOURCES unit/test_dive_format.cpp LIBS caracara_core)
# The failsafe policy and the [failsafe] table.
caracara_unit_test(test_failsafe SOURCES unit/test_failsafe.cpp LIBS caracara_core)
