// toml++'s implementation compiled into the config harness: Debian ships the parser as
// libtomlplusplus.so, which is not instrumented, so the fuzzer would see no coverage inside it
// and ASan could not watch its memory. Same macros as the library build (pkg-config's), so the
// definitions here simply take the shared library's place.
#define TOML_IMPLEMENTATION
#include <toml++/toml.h>
