# core/: one test program per piece of pure logic.
caracara_unit_test(test_mixing SOURCES unit/test_mixing.cpp LIBS caracara_core)
# core/frames: every edge's axes against the seed's axis table, orientations in ENU and NED.
caracara_unit_test(test_frames SOURCES unit/test_frames.cpp LIBS caracara_core)
caracara_unit_test(test_budget SOURCES unit/test_budget.cpp LIBS caracara_core)
caracara_unit_test(test_packet SOURCES unit/test_packet.cpp LIBS caracara_core)
caracara_unit_test(test_safety SOURCES unit/test_safety.cpp LIBS caracara_core)
caracara_unit_test(test_config SOURCES unit/test_config.cpp LIBS caracara_core)
# The shipped example must stay a valid config: the test parses it.
target_compile_definitions(test_config PRIVATE
  CARACARA_EXAMPLE_CONFIG="${CMAKE_SOURCE_DIR}/daemon/caracarad.toml.example")
caracara_unit_test(test_direction_judgement SOURCES unit/test_direction_judgement.cpp LIBS caracara_core)
# The bus scan: what it probes, its verdicts, a probe reply told SeaBotix from legacy.
caracara_unit_test(test_bus_scan_report SOURCES unit/test_bus_scan_report.cpp LIBS caracara_devices)
# Every enum's names (core/enum_names.hpp), wherever the enum lives.
caracara_unit_test(test_enum_names SOURCES unit/test_enum_names.cpp LIBS caracara_daemon caracara_simcore)
# It reads the sources for every EnumNames table, so that none is left out of its list.
target_compile_definitions(test_enum_names PRIVATE CARACARA_SOURCE_DIR="${CMAKE_SOURCE_DIR}")
# core/vehicle_geometry: a Wrench in newtons through thruster positions, directions and force curve.
caracara_unit_test(test_vehicle_geometry SOURCES unit/test_vehicle_geometry.cpp LIBS caracara_core)
