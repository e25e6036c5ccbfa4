// The one command-line parser of the tools (evaluate, success_ratio, cut_bag, demo_report): switches,
// options with a typed and checked value, positional arguments, and --help / -h printing the tool's
// usage. Every problem is one line "<program>: <message>" on stderr, then a pointer to --help.
#pragma once

#include <charconv>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <system_error>
#include <type_traits>
#include <vector>

namespace hglasm_odometry {

class ArgumentParser {
 public:
  enum class Result { kOk, kHelp, kError };
  /// Reads an option's value; false with *error (e.g. "expected X,Y,YAW") for a bad one.
  using ValueParser = std::function<bool(const std::string& text, std::string* error)>;

  /// `program` starts every message; `usage` is what --help prints.
  ArgumentParser(std::string program, std::string usage);

  /// A switch: given, *value becomes `set_to` (true for --quiet, false for --no-odom).
  void addFlag(const std::string& name, bool* value, bool set_to = true);
  /// Options with a value. `given`, when not null, becomes true when the option is given.
  void addOption(const std::string& name, std::string* value, bool* given = nullptr);
  /// A finite number.
  void addOption(const std::string& name, double* value, bool* given = nullptr);
  /// A decimal integer (the whole text) of at least `min`.
  template <typename Integer, typename = std::enable_if_t<std::is_integral_v<Integer>>>
  void addOption(const std::string& name, Integer* value, Integer min = std::numeric_limits<Integer>::min(),
                 bool* given = nullptr) {
    addOption(name, [value, min, given](const std::string& text, std::string* error) {
      Integer parsed = 0;
      const char* end = text.data() + text.size();
      const auto result = std::from_chars(text.data(), end, parsed);
      if (text.empty() || result.ec != std::errc() || result.ptr != end || parsed < min) {
        const std::string expected = min != std::numeric_limits<Integer>::min()
                                         ? "an integer >= " + std::to_string(min)
                                     : std::is_signed_v<Integer> ? "an integer"
                                                                 : "a non-negative integer";
        *error = "expected " + expected + ", got '" + text + "'";
        return false;
      }
      *value = parsed;
      if (given) *given = true;
      return true;
    });
  }
  void addOption(const std::string& name, ValueParser parse);
  /// Arguments that are not options land in *values; without this call they are errors.
  void addPositionals(std::vector<std::string>* values);

  /// Parses argv[1 .. argc-1]. --help / -h prints the usage on stdout: kHelp. A problem: kError.
  Result parse(int argc, char** argv) const;
  Result parse(const std::vector<std::string>& arguments) const;

  /// Prints "<program>: <message>" and the pointer to --help on stderr; false. For the tools' own checks.
  bool fail(const std::string& message) const;

 private:
  struct Option {
    bool takes_value = true;
    ValueParser parse;
  };
  std::string program_;
  std::string usage_;
  std::map<std::string, Option> options_;
  std::vector<std::string>* positionals_ = nullptr;
};

/// Exit status of a tool for a parse that did not return kOk: 0 after --help, 2 after an error.
inline int exitStatus(ArgumentParser::Result result) {
  return result == ArgumentParser::Result::kHelp ? 0 : 2;
}

}  // namespace hglasm_odometry
