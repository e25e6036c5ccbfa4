#include "hglasm_odometry/tools/argument_parser.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <utility>

namespace hglasm_odometry {

ArgumentParser::ArgumentParser(std::string program, std::string usage)
    : program_(std::move(program)), usage_(std::move(usage)) {}

void ArgumentParser::addFlag(const std::string& name, bool* value, bool set_to) {
  options_[name] = Option{false, [value, set_to](const std::string&, std::string*) {
                            *value = set_to;
                            return true;
                          }};
}

void ArgumentParser::addOption(const std::string& name, std::string* value, bool* given) {
  addOption(name, [value, given](const std::string& text, std::string*) {
    *value = text;
    if (given) *given = true;
    return true;
  });
}

void ArgumentParser::addOption(const std::string& name, double* value, bool* given) {
  addOption(name, [value, given](const std::string& text, std::string* error) {
    // strtod, not floating-point std::from_chars: GCC 9's libstdc++ (ROS Noetic) has none.
    char* end = nullptr;
    const double parsed = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0' || !std::isfinite(parsed)) {
      *error = "not a number: '" + text + "'";
      return false;
    }
    *value = parsed;
    if (given) *given = true;
    return true;
  });
}

void ArgumentParser::addOption(const std::string& name, ValueParser parse) {
  options_[name] = Option{true, std::move(parse)};
}

void ArgumentParser::addPositionals(std::vector<std::string>* values) { positionals_ = values; }

ArgumentParser::Result ArgumentParser::parse(int argc, char** argv) const {
  return parse(std::vector<std::string>(argv + std::min(argc, 1), argv + argc));
}

ArgumentParser::Result ArgumentParser::parse(const std::vector<std::string>& arguments) const {
  const auto error = [this](const std::string& message) {
    fail(message);
    return Result::kError;
  };
  for (std::size_t i = 0; i < arguments.size(); ++i) {
    const std::string& argument = arguments[i];
    if (argument == "--help" || argument == "-h") {
      std::cout << usage_;
      return Result::kHelp;
    }
    const auto option = options_.find(argument);
    if (option == options_.end()) {
      if (argument.size() > 1 && argument[0] == '-') return error("unknown option '" + argument + "'");
      if (!positionals_) return error("unexpected argument '" + argument + "'");
      positionals_->push_back(argument);
      continue;
    }
    if (option->second.takes_value && i + 1 >= arguments.size()) return error(argument + " needs a value");
    const std::string value = option->second.takes_value ? arguments[++i] : std::string();
    std::string message;
    if (!option->second.parse(value, &message)) return error(argument + ": " + message);
  }
  return Result::kOk;
}

bool ArgumentParser::fail(const std::string& message) const {
  std::cerr << program_ << ": " << message << "\n(" << program_ << " --help for usage)\n";
  return false;
}

}  // namespace hglasm_odometry
