#pragma once
// Shared by the test modules: what a call that must refuse its input says.

#include <functional>
#include <initializer_list>
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

/// A file of a malformed-input corpus and the message it must give after "path:".
struct BadCase {
  const char* file;
  const char* expected;
};

/// Every case's `directory/file` given to `read` must be refused with exactly
/// "directory/file" + messageSuffix + ":" + expected (the suffix for readers that take a
/// directory and name a file in it).
inline void expectCorpus(const std::string& directory, std::initializer_list<BadCase> cases,
                         const std::function<void(const std::string&)>& read, const std::string& messageSuffix = "") {
  for (const BadCase& c : cases) {
    const std::string path = directory + "/" + c.file;
    EXPECT_EQ(errorOf([&] { read(path); }), path + messageSuffix + ":" + c.expected) << c.file;
  }
}

}  // namespace drape::testing
