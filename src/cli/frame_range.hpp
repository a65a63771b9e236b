#pragma once
// `--range FIRST:LAST` (also `FIRST:`, `:LAST` and `FRAME`): the frames of a run a command
// works on, 0-based and inclusive, as `drape render` and `drape inspect` take them.

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "command.hpp"
#include "drape/core/error.hpp"

namespace drape::cli {

struct FrameRange {
  std::int64_t first = 0;
  std::int64_t last = -1;  ///< -1: the run's last frame
};

/// Throws drape::Error naming the option and what it expects on anything else.
[[nodiscard]] inline FrameRange parseFrameRange(const std::string& text, std::string_view option = "--range") {
  const auto bad = [&] {
    return Error(fmt::format("{} {} is not a range: expected FIRST:LAST, FIRST: (to the end), :LAST or one FRAME, "
                             "frame numbers from 0",
                             option, text));
  };
  const auto number = [&](std::string_view part, std::int64_t fallback) {
    if (part.empty()) return fallback;
    const std::optional<long long> value = wholeNumber(part, 0, std::numeric_limits<std::int64_t>::max());
    if (!value) throw bad();
    return static_cast<std::int64_t>(*value);
  };
  const std::string_view all(text);
  const std::size_t colon = all.find(':');
  if (colon == std::string_view::npos) {
    if (all.empty()) throw bad();
    const std::int64_t frame = number(all, 0);
    return {frame, frame};
  }
  return {number(all.substr(0, colon), 0), number(all.substr(colon + 1), -1)};
}

}  // namespace drape::cli
