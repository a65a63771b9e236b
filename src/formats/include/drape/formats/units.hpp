#pragma once
// Length units of files from outside. drape works in metres; readers scale on load.

#include <string>

namespace drape::formats {

/// Metres per unit for "m", "dm", "cm", "mm", "in" (also "ft"). Throws drape::Error
/// naming `option` for anything else.
[[nodiscard]] double metresPerUnit(const std::string& unit, const std::string& option = "--units");

}  // namespace drape::formats
