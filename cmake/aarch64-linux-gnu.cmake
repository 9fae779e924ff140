# Cross build for arm64 (the vehicle's Raspberry Pi class board) on an amd64 Debian machine,
# with Debian's multiarch: the :arm64 -dev packages in /usr/lib/aarch64-linux-gnu and the
# shared /usr/include, as `dpkg-buildpackage -a arm64` uses them (scripts/cross_test.sh
# installs what it needs).
#
#   cmake -S . -B build-arm64 -DCMAKE_TOOLCHAIN_FILE=cmake/aarch64-linux-gnu.cmake
#   cmake --build build-arm64 && ctest --test-dir build-arm64 -LE 'system|kernel'
#
# ctest runs the arm64 test programs under qemu-user (no binfmt_misc needed), and the tests
# start the built daemon, simulator and caracaractl through the same emulator
# (CARACARA_TEST_EMULATOR, tests/CMakeLists.txt); dbus-daemon, busctl and python3 stay native.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
# pkgconf:arm64's wrapper: the .pc files of /usr/lib/aarch64-linux-gnu/pkgconfig only.
set(PKG_CONFIG_EXECUTABLE aarch64-linux-gnu-pkg-config CACHE FILEPATH "pkg-config for arm64")
# No -L /usr/aarch64-linux-gnu: the programs run with libc6:arm64 (pulled in by the :arm64
# -dev packages, the C library a Raspberry Pi's Debian has), found at its own multiarch path.
# With -L, qemu 7.2 loads libc6-arm64-cross (2.36-8cross1) instead, and there a fork()ed
# child spins forever before it can exec (the integration tests fork the simulator).
set(CMAKE_CROSSCOMPILING_EMULATOR qemu-aarch64-static)
