// Helpers shared by the Catch2 test files (not part of the library).
#pragma once

#include "hemilight/error.hpp"

#include <catch2/catch.hpp>

#include <string>

namespace hemilight::test {

/// A path in the test scratch directory (build/tests/tmp).
inline std::string tmp_path(const std::string& name) { return std::string(HEMILIGHT_TEST_TMPDIR) + "/" + name; }

/// Checks that f() throws hemilight::error with the given code and a message containing `needle`.
template <class F>
void require_error(F&& f, status code, const std::string& needle) {
  try {
    f();
    FAIL("no exception thrown; expected one containing '" << needle << "'");
  } catch (const error& e) {
    INFO("message: " << e.what());
    CHECK(e.code() == code);
    CHECK(std::string(e.what()).find(needle) != std::string::npos);
  }
}

}  // namespace hemilight::test
