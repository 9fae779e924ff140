// Catch2 2 only: Catch2 3 brings its own main (Catch2::Catch2WithMain).
#define CATCH_CONFIG_MAIN
#include "tests/catch.hpp"
