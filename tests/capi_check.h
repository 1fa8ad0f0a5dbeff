/* CHECK and CHECK_FAILS for the C99 tests of the C ABI (test_capi*.c).
 * Each test file is its own program and includes this once. */
#ifndef HEMILIGHT_CAPI_CHECK_H
#define HEMILIGHT_CAPI_CHECK_H

#ifndef HEMILIGHT_CAPI_OLDER_LAYOUT_H /* test_capi_abi.c declares an older header's copy itself */
#include "hemilight.h"
#endif

#include <stdio.h>
#include <string.h>

static int passed = 0, failed = 0;

#define CHECK(cond)                                                        \
  do {                                                                     \
    if (cond) {                                                            \
      ++passed;                                                            \
    } else {                                                               \
      ++failed;                                                            \
      printf("FAILED %s:%d: %s\n", __FILE__, __LINE__, #cond);             \
    }                                                                      \
  } while (0)

/* A failing call returns `expected` and sets a message that contains `needle`. */
#define CHECK_FAILS(call, expected, needle)                                                  \
  do {                                                                                       \
    hemilight_status st_ = (call);                                                           \
    CHECK(st_ == (expected));                                                                \
    CHECK(strstr(hemilight_last_error(), (needle)) != NULL);                                 \
    if (st_ != (expected) || strstr(hemilight_last_error(), (needle)) == NULL)               \
      printf("  call: %s\n  status %d, message: %s\n", #call, (int)st_, hemilight_last_error()); \
  } while (0)

#endif
