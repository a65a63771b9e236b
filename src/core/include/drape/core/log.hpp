#pragma once
// Logging: spdlog to standard error. Results go to files or standard output; diagnostics,
// progress and warnings go here.

#include <spdlog/spdlog.h>

namespace drape {

/// verbosity: -1 quiet (errors only), 0 normal (warnings and info), 1 verbose, 2 trace.
void setupLogging(int verbosity);

}  // namespace drape
