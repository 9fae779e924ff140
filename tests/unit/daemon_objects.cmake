# The daemon's objects (Vehicle, ControlLoop, ThrusterBus with its BusWorker) in process, on the
# fakes of the device seam in tests/unit/fakes/ (no processes): each judged by its fake wire.
add_library(daemon_fakes STATIC unit/fakes/fake_device_io.cpp unit/fakes/fake_gpio.cpp unit/fakes/daemon_rig.cpp)
target_link_libraries(daemon_fakes PUBLIC caracara_daemon)
caracara_unit_test(test_vehicle SOURCES unit/test_vehicle.cpp LIBS daemon_fakes)
caracara_unit_test(test_control_loop SOURCES unit/test_control_loop.cpp LIBS daemon_fakes)
caracara_unit_test(test_thruster_bus SOURCES unit/test_thruster_bus.cpp LIBS daemon_fakes)
caracara_unit_test(test_teensy_worker SOURCES unit/test_teensy_worker.cpp LIBS daemon_fakes)
caracara_unit_test(test_preflight SOURCES unit/test_preflight.cpp LIBS daemon_fakes)
caracara_unit_test(test_failsafe_table SOURCES unit/test_failsafe_table.cpp LIBS daemon_fakes)
# The bus recovery and a lost bus, judged by the fake wire's bus clear and orders.
caracara_unit_test(test_bus_recovery_steps SOURCES unit/test_bus_recovery_steps.cpp LIBS daemon_fakes)
caracara_unit_test(test_bus_loss SOURCES unit/test_bus_loss.cpp LIBS daemon_fakes)
# CommandAcceptance: every command in every state, accepted or its named error, in order.
caracara_unit_test(test_command_acceptance SOURCES unit/test_command_acceptance.cpp LIBS daemon_fakes)
# The D-Bus objects (dbus/) on a private dbus-daemon, serving the daemon's objects on the fakes.
add_library(service_rig STATIC unit/fakes/service_rig.cpp)
target_link_libraries(service_rig PUBLIC daemon_fakes caracara_vehicle_dbus sim_fixture)
caracara_unit_test(test_vehicle_object SOURCES unit/test_vehicle_object.cpp LIBS service_rig)
caracara_unit_test(test_failsafe_clearance SOURCES unit/test_failsafe_clearance.cpp LIBS service_rig)
caracara_unit_test(test_thruster_object SOURCES unit/test_thruster_object.cpp LIBS service_rig)
caracara_unit_test(test_i2c_bus_object SOURCES unit/test_i2c_bus_object.cpp LIBS service_rig)
caracara_unit_test(test_teensy_object SOURCES unit/test_teensy_object.cpp LIBS service_rig)
caracara_unit_test(test_client_tracker SOURCES unit/test_client_tracker.cpp LIBS service_rig)
caracara_unit_test(test_announcer SOURCES unit/test_announcer.cpp LIBS caracara_vehicle_dbus)
caracara_unit_test(test_vehicle_service SOURCES unit/test_vehicle_service.cpp LIBS service_rig)
caracara_unit_test(test_error_reply SOURCES unit/test_error_reply.cpp LIBS service_rig)
# The event loop's own pieces (daemon/loop/), each on an sd-event loop of its own.
caracara_unit_test(test_deadline_timer SOURCES unit/test_deadline_timer.cpp LIBS caracara_daemon)
caracara_unit_test(test_loop_waker SOURCES unit/test_loop_waker.cpp LIBS caracara_daemon)
caracara_unit_test(test_service_status SOURCES unit/test_service_status.cpp LIBS daemon_fakes)
caracara_unit_test(test_motor_test SOURCES unit/test_motor_test.cpp LIBS daemon_fakes)
caracara_unit_test(test_bus_scan SOURCES unit/test_bus_scan.cpp LIBS daemon_fakes)
caracara_unit_test(test_teensy_port SOURCES unit/test_teensy_port.cpp LIBS daemon_fakes)
# The Teensy's link on the simulator's own Teensy model behind the SPI side of the seam.
add_library(teensy_fakes STATIC unit/fakes/fake_teensy_io.cpp)
target_link_libraries(teensy_fakes PUBLIC daemon_fakes caracara_simcore)
caracara_unit_test(test_teensy_connection SOURCES unit/test_teensy_connection.cpp LIBS teensy_fakes)
caracara_unit_test(test_teensy_turn SOURCES unit/test_teensy_turn.cpp LIBS teensy_fakes)
caracara_unit_test(test_announced_object SOURCES unit/test_announced_object.cpp LIBS service_rig)
caracara_unit_test(test_bus_input_probe SOURCES unit/test_bus_input_probe.cpp LIBS service_rig)
caracara_unit_test(test_attitude_samples SOURCES unit/test_attitude_samples.cpp LIBS caracara_daemon)
# Direction detection (and the dive that records it) on a vehicle in the pool (PoolVehicle) that
# the thrusters on the fake wire turn, as the Teensy's model reports it.
caracara_unit_test(test_direction_detection SOURCES unit/test_direction_detection.cpp unit/fakes/pool_vehicle.cpp LIBS teensy_fakes)
caracara_unit_test(test_dive_recorder SOURCES unit/test_dive_recorder.cpp unit/fakes/pool_vehicle.cpp LIBS teensy_fakes)
caracara_unit_test(test_log SOURCES unit/test_log.cpp unit/fakes/stderr_lines.cpp LIBS caracara_daemon)
caracara_unit_test(test_thread_schedule SOURCES unit/test_thread_schedule.cpp unit/fakes/stderr_lines.cpp LIBS caracara_daemon)
caracara_unit_test(test_cold_libraries SOURCES unit/test_cold_libraries.cpp LIBS caracara_daemon)
# Under qemu-user (a cross build's tests) smaps shows the emulator's mappings, not the program's;
# under AddressSanitizer mlock is a no-op and caracarad never locks.
target_compile_definitions(test_cold_libraries PRIVATE CARACARA_TEST_EMULATED=$<BOOL:${CMAKE_CROSSCOMPILING_EMULATOR}>
                           CARACARA_TEST_ASAN=$<BOOL:${CARACARA_SANITIZE}>)
target_compile_definitions(test_thread_schedule PRIVATE CARACARA_TEST_ASAN=$<BOOL:${CARACARA_SANITIZE}>)
