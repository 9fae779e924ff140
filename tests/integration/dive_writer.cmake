# The dive writer's rotation on real files (tests/integration/test_dive_writer.cpp).
caracara_integration_test(test_dive_writer SOURCES integration/test_dive_writer.cpp LIBS caracara_daemon)
