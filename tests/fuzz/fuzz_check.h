/* SPDX-License-Identifier: MIT */
/* A property that must hold in a fuzz target: on failure, print it and abort (libFuzzer then saves the
 * input that broke it as a crash). */
#ifndef POUR_FUZZ_CHECK_H
#define POUR_FUZZ_CHECK_H

#include <cstdio>
#include <cstdlib>

#define FUZZ_CHECK(cond, ...)                                          \
  do {                                                                 \
    if (!(cond)) {                                                     \
      std::fprintf(stderr, "%s:%d: property broken: %s: ", __FILE__, __LINE__, #cond); \
      std::fprintf(stderr, __VA_ARGS__);                               \
      std::fputc('\n', stderr);                                        \
      std::abort();                                                    \
    }                                                                  \
  } while (0)

#endif /* POUR_FUZZ_CHECK_H */
