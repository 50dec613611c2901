#include "redres/run/record.hpp"

#include <charconv>
#include <stdexcept>

namespace redres {

RecordOptions parse_record(const std::string& text) {
  RecordOptions r;
  if (text == "all") return r;
  if (text == "none") {
    r.none = true;
    return r;
  }
  const std::string prefix = "every=";
  if (text.rfind(prefix, 0) == 0) {
    const std::string digits = text.substr(prefix.size());
    std::size_t n = 0;
    const auto res = std::from_chars(digits.data(), digits.data() + digits.size(), n);
    if (res.ec == std::errc() && res.ptr == digits.data() + digits.size() && n >= 1) {
      r.every = n;
      return r;
    }
  }
  throw std::invalid_argument("record: expected \"all\", \"none\" or \"every=N\" with an integer N >= 1, got \"" +
                              text + "\"");
}

RecordOptions read_record(const TableReader& table, std::string_view key, std::string_view fallback) {
  try {
    return parse_record(table.string(key, fallback));
  } catch (const std::invalid_argument& e) {
    table.fail(key, e.what());
  }
}

TrajectoryFormat parse_format(const std::string& text) {
  for (const auto& [format, name] : enum_names(TrajectoryFormat{})) {
    if (text == name) return format;
  }
  throw std::invalid_argument("expected \"csv\" or \"hdf5\", got \"" + text + "\"");
}

}  // namespace redres
