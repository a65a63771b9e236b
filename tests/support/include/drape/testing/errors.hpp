#pragma once
// Shared by the test modules: what a call that must refuse its input says.

#include <functional>
#include <string>

#include <gtest/gtest.h>

#include "drape/core/error.hpp"

namespace drape::testing {

/// Runs `f`, expects it to throw a drape::Error for bad input (exit code 2) and returns the
/// message; "(no error)" when it throws none, so that a message check fails readably.
inline std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::BadInput) << e.what();
    return e.what();
  }
  return "(no error)";
}

}  // namespace drape::testing
