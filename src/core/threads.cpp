#include "drape/core/threads.hpp"

#include <tbb/global_control.h>

namespace drape {

std::size_t threadsAllowed() {
  return tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
}

}  // namespace drape
