// The harnesses' invariant check: a failed one prints what was expected and aborts, which
// libFuzzer reports as a crash and saves the input (crash-<sha1>) for the regression corpus.
#pragma once

#include <cstdio>
#include <cstdlib>

#define FUZZ_CHECK(cond, ...)                                                                   \
    do {                                                                                        \
        if (!(cond)) {                                                                          \
            std::fprintf(stderr, "%s:%d: invariant failed: %s: ", __FILE__, __LINE__, #cond);  \
            std::fprintf(stderr, __VA_ARGS__);                                                  \
            std::fputc('\n', stderr);                                                           \
            std::abort();                                                                       \
        }                                                                                       \
    } while (0)
