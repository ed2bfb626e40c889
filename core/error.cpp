#include "core/error.hpp"

namespace fdem {

void internal_error(const char* file, int line, const std::string& what) {
  throw std::logic_error(std::string("fdem internal error at ") + file + ":" +
                         std::to_string(line) + ": " + what +
                         " (please report this with the scene that triggered it)");
}

}  // namespace fdem
