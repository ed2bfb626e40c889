// Scene builders for the verification tests: the shared ones of drivers/scene_builders.hpp.
#pragma once

#include "drivers/scene_builders.hpp"

namespace fdem::testing {
using namespace fdem::builders;
}  // namespace fdem::testing
