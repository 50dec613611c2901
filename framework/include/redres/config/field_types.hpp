#pragma once
/// @file
/// The types a Config's schema (config.hpp) is described in and reports with: the error of a value that breaks a
/// rule (FieldError), per-joint values (PerJoint), how a key must be given (Presence), a key and a table as listed
/// (KeyInfo, KeyTable), and a validity rule (Rule).

#include <functional>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace redres {

/// A configuration value that breaks a rule: the key and what was expected. Thrown by validation; the TOML path
/// turns it into a ConfigError at the key's file:line:col, the C++ path into std::invalid_argument.
class FieldError : public std::invalid_argument {
 public:
  /// what() is "[<who>: ]key '<key>': <message>".
  FieldError(std::string key, const std::string& message, const std::string& who = "")
      : std::invalid_argument((who.empty() ? "" : who + ": ") + "key '" + key + "': " + message),
        key_(std::move(key)),
        message_(message) {}
  /// The offending key ("" for the table as a whole).
  [[nodiscard]] const std::string& key() const noexcept { return key_; }
  /// What was expected, without the key.
  [[nodiscard]] const std::string& message() const noexcept { return message_; }

 private:
  std::string key_;
  std::string message_;
};

/// One number for every joint (or task row), or one number per joint. Resolved against the robot by the plugin.
struct PerJoint {
  std::vector<double> values;  //!< one entry (broadcast) or one per joint

  PerJoint() = default;
  PerJoint(double v) : values{v} {}  // NOLINT(google-explicit-constructor): `.margin = 0.02` reads naturally
  PerJoint(std::initializer_list<double> v) : values(v) {}
  explicit PerJoint(std::vector<double> v) : values(std::move(v)) {}

  /// The n values; throws FieldError(key) unless there are 1 or n entries.
  [[nodiscard]] Eigen::VectorXd resolve(int n, const std::string& key, const std::string& what = "joint") const;
};

/// How a key must be given.
enum class Presence {
  kOptional,  //!< has a default
  kRequired,  //!< must be given
  kGroup,     //!< one of a group of alternatives (the schema's group rule says which)
};

/// One key as listed by `redres plugins` and the docs.
struct KeyInfo {
  std::string name;          //!< TOML key
  std::string default_text;  //!< the default as TOML text ("" when required or in a group)
  std::string unit;          //!< e.g. "m", "1/s", "" when dimensionless
  std::string help;          //!< what it means
  std::string rule;          //!< validity rule, e.g. "> 0" ("" when any value of the type is valid)
  std::string type;          //!< "number", "integer", "string", "one of 'a', 'b'", ...
  Presence presence = Presence::kOptional;
  std::string group;  //!< the group's name when presence is kGroup
};

/// One table of an input file and its keys, as `redres keys` and the docs list them.
struct KeyTable {
  std::string file;   //!< "scenario", "robot" or "sweep"
  std::string table;  //!< "" for the file's top level, else e.g. "[output]" or "[[joints]]"
  std::string help;   //!< what the table is for
  std::vector<KeyInfo> keys;
};

/// A validity rule for a value of type T: `ok` returns true when valid; `text` says what is expected.
template <class T>
struct Rule {
  std::string text;                  //!< e.g. "> 0"
  std::function<bool(const T&)> ok;  //!< the test
};

}  // namespace redres
