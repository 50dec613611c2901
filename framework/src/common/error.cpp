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

namespace redres {

namespace {

// The length of the UTF-8 sequence starting at text[i] and its code point, or 0 when it is not well-formed.
std::size_t utf8_sequence(std::string_view text, std::size_t i, char32_t& code) noexcept {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char b0 = byte(i);
  std::size_t length = 0;
  char32_t min = 0;
  if (b0 < 0x80) {
    code = b0;
    return 1;
  }
  if ((b0 & 0xE0) == 0xC0) {
    length = 2, code = b0 & 0x1F, min = 0x80;
  } else if ((b0 & 0xF0) == 0xE0) {
    length = 3, code = b0 & 0x0F, min = 0x800;
  } else if ((b0 & 0xF8) == 0xF0) {
    length = 4, code = b0 & 0x07, min = 0x10000;
  } else {
    return 0;
  }
  if (i + length > text.size()) return 0;
  for (std::size_t k = 1; k < length; ++k) {
    if ((byte(i + k) & 0xC0) != 0x80) return 0;
    code = (code << 6) | (byte(i + k) & 0x3F);
  }
  if (code < min || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return 0;
  return length;
}

bool is_control(char32_t c) noexcept { return c < 0x20 || (c >= 0x7F && c <= 0x9F); }

}  // namespace

bool is_utf8(std::string_view text) noexcept {
  char32_t code = 0;
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t n = utf8_sequence(text, i, code);
    if (n == 0) return false;
    i += n;
  }
  return true;
}

bool is_printable_name(std::string_view name) noexcept {
  if (name.empty()) return false;
  char32_t code = 0;
  for (std::size_t i = 0; i < name.size();) {
    const std::size_t n = utf8_sequence(name, i, code);
    if (n == 0 || is_control(code)) return false;
    i += n;
  }
  return true;
}

std::string printable(std::string_view text) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(text.size());
  char32_t code = 0;
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t n = utf8_sequence(text, i, code);
    if (n != 0 && (!is_control(code) || code == '\n' || code == '\t')) {
      out.append(text.substr(i, n));
      i += n;
      continue;
    }
    const std::size_t bad = n == 0 ? 1 : n;  // a control character's bytes, or the one byte that is not UTF-8
    for (std::size_t k = 0; k < bad; ++k) {
      const auto b = static_cast<unsigned char>(text[i + k]);
      out += "\\x";
      out += kHex[b >> 4];
      out += kHex[b & 0xF];
    }
    i += bad;
  }
  return out;
}

}  // namespace redres
