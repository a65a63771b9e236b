#include "drape/formats/units.hpp"

#include <fmt/format.h>

#include "drape/core/error.hpp"

namespace drape::formats {

double metresPerUnit(const std::string& unit, const std::string& option) {
  if (unit == "m") return 1.0;
  if (unit == "dm") return 0.1;
  if (unit == "cm") return 0.01;
  if (unit == "mm") return 0.001;
  if (unit == "in") return 0.0254;
  if (unit == "ft") return 0.3048;
  throw Error(fmt::format("{}: unknown unit '{}' (expected m, dm, cm, mm, in or ft)", option, unit));
}

}  // namespace drape::formats
