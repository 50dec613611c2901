#pragma once
/// @file
/// Writing a text into a std::string without ever growing it: the diagnosis of a failed step is written on the
/// real-time path into storage reserved at setup (kDiagnosisCapacity), so a failed step allocates no more than a
/// solved one. Numbers go through std::to_chars (as an ostream would print them at the same precision); a text that
/// does not fit is cut, and the cut is marked with " [...]".

#include <charconv>
#include <cstddef>
#include <string>
#include <string_view>
#include <type_traits>

namespace redres {

/// The capacity reserved for a step's diagnosis (SolverInfo::diagnosis) at setup, in bytes.
inline constexpr std::size_t kDiagnosisCapacity = 4096;

/// Gives a diagnosis string its reserved capacity back if something (an assignment from a temporary, a caller's own
/// StepOutput) took it: allocates only then, never on a string that kept it.
inline void keep_diagnosis_capacity(std::string& s) {
  if (s.capacity() < kDiagnosisCapacity) s.reserve(kDiagnosisCapacity);
}

/// Appends to a string within the capacity it had when the sink was made.
class TextSink {
 public:
  /// Appends to `out` (which keeps what it holds) up to its capacity now.
  explicit TextSink(std::string& out) noexcept : out_(out), capacity_(out.capacity()) {}

  /// Significant digits of the floating-point numbers written next (6, as an ostream's default).
  TextSink& precision(int digits) noexcept {
    precision_ = digits < 1 ? 1 : (digits > 17 ? 17 : digits);  // 17 digits hold any double; the buffer holds them
    return *this;
  }
  TextSink& operator<<(std::string_view s) noexcept {
    put(s);
    return *this;
  }
  TextSink& operator<<(const char* s) noexcept { return *this << std::string_view(s); }
  TextSink& operator<<(const std::string& s) noexcept { return *this << std::string_view(s); }
  TextSink& operator<<(char c) noexcept { return *this << std::string_view(&c, 1); }
  template <class T,
            std::enable_if_t<std::is_integral_v<T> && !std::is_same_v<T, char> && !std::is_same_v<T, bool>, int> = 0>
  TextSink& operator<<(T v) noexcept {
    char buf[24];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    return *this << std::string_view(buf, static_cast<std::size_t>(r.ptr - buf));
  }
  TextSink& operator<<(double v) noexcept {
    char buf[40];
    const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, precision_);
    if (r.ec != std::errc()) return *this << "?";
    return *this << std::string_view(buf, static_cast<std::size_t>(r.ptr - buf));
  }
  /// Whether something was cut.
  [[nodiscard]] bool cut() const noexcept { return cut_; }
  /// The string written to.
  [[nodiscard]] std::string& str() noexcept { return out_; }

 private:
  static constexpr std::string_view kMark = " [...]";
  void put(std::string_view s) noexcept {
    if (cut_) return;
    const std::size_t room = capacity_ > out_.size() + kMark.size() ? capacity_ - out_.size() - kMark.size() : 0;
    if (s.size() <= room) {
      out_.append(s);
      return;
    }
    out_.append(s.substr(0, room));
    if (out_.size() + kMark.size() <= capacity_) out_.append(kMark);
    cut_ = true;
  }

  std::string& out_;
  std::size_t capacity_;
  int precision_ = 6;
  bool cut_ = false;
};

/// What `write(TextSink&)` writes, as a string (the allocating form of a text written into a sink, for callers off
/// the real-time path).
template <class Write>
[[nodiscard]] std::string text_of(Write&& write) {
  std::string out;
  out.reserve(kDiagnosisCapacity);
  TextSink sink(out);
  write(sink);
  return out;
}

}  // namespace redres
