#include "redres/common/error.hpp"

namespace redres {

std::string SourceLocation::str() const {
  if (line == 0) return file;
  return file + ":" + std::to_string(line) + ":" + std::to_string(column);
}

namespace {
std::string format(const SourceLocation& where, const std::string& message) {
  const std::string loc = where.str();
  return loc.empty() ? message : loc + ": " + message;
}
}  // namespace

ConfigError::ConfigError(SourceLocation where, const std::string& message)
    : std::runtime_error(format(where, message)), where_(std::move(where)), detail_(message) {}

void throw_invalid_argument(const char* function, const std::string& condition) {
  throw std::invalid_argument(std::string(function) + ": " + condition);
}

}  // namespace redres
