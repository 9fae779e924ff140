# The libgpiod backend of this build (v1 on libgpiod 1.6, v2 on libgpiod 2.x): the same test for both.
caracara_unit_test(test_libgpiod_backend SOURCES unit/test_libgpiod_backend.cpp LIBS caracara_platform)
