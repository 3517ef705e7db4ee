// The fuzzers' oracle: a failed check names itself, then aborts (the fuzzer's crash).
#pragma once

#include <cstdio>
#include <cstdlib>

#define JLE_FUZZ_CHECK(ok)                                                        \
  do {                                                                            \
    if (!(ok)) {                                                                  \
      std::fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #ok); \
      std::abort();                                                               \
    }                                                                             \
  } while (false)
