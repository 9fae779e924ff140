caracara_unit_test(test_teensy SOURCES unit/test_teensy.cpp LIBS caracara_protocol)
