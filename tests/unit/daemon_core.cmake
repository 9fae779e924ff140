caracara_unit_test(test_daemon_core
  SOURCES unit/test_mixing.cpp unit/test_budget.cpp unit/test_packet.cpp unit/test_safety.cpp unit/test_config.cpp
  LIBS caracara_core)
# The shipped example must stay a valid config: the test parses it.
target_compile_definitions(test_daemon_core PRIVATE
  CARACARA_EXAMPLE_CONFIG="${CMAKE_SOURCE_DIR}/daemon/caracarad.toml.example")
