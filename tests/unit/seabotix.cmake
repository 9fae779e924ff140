caracara_unit_test(test_seabotix SOURCES unit/test_seabotix.cpp LIBS caracara_protocol)
