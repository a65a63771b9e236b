#include "drape/scene/avatar.hpp"
