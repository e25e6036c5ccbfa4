#include "hglasm_odometry/core/parameter_source.h"

#include <cmath>
#include <sstream>
#include <utility>

namespace hglasm {
namespace {

std::string formatNumber(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

bool startsWith(const std::string& text, const std::string& prefix) {
  return text.compare(0, prefix.size(), prefix) == 0;
}

/// What a number within [lo, hi] is called in a message.
std::string numberRequirement(double lo, double hi, bool positive, bool allow_inf) {
  std::string requirement;
  if (positive && hi == kInfinity) {
    requirement = "a positive number";
  } else if (lo == 0.0 && hi == kInfinity) {
    requirement = "a non-negative number";
  } else if (lo == -kInfinity && hi == kInfinity) {
    requirement = "a finite number";
  } else {
    requirement = "a number in [" + formatNumber(lo) + ", " + formatNumber(hi) + "]";
    if (positive) requirement += " and > 0";
  }
  if (allow_inf) requirement += " (or .inf)";
  return requirement;
}

/// The value of an int or a double; false for any other type.
bool numberOf(const ParameterValue& value, double* number) {
  if (value.type == ParameterValue::Type::kInt) {
    *number = value.integer;
  } else if (value.type == ParameterValue::Type::kDouble) {
    *number = value.number;
  } else {
    return false;
  }
  return true;
}

}  // namespace

ParameterValue ParameterValue::ofBool(bool value) {
  ParameterValue result = ofType(Type::kBool);
  result.boolean = value;
  return result;
}
ParameterValue ParameterValue::ofInt(int value) {
  ParameterValue result = ofType(Type::kInt);
  result.integer = value;
  return result;
}
ParameterValue ParameterValue::ofDouble(double value) {
  ParameterValue result = ofType(Type::kDouble);
  result.number = value;
  return result;
}
ParameterValue ParameterValue::ofString(std::string value) {
  ParameterValue result = ofType(Type::kString);
  result.text = std::move(value);
  return result;
}
ParameterValue ParameterValue::ofType(Type type) {
  ParameterValue result;
  result.type = type;
  return result;
}

std::string ParameterValue::describe() const {
  switch (type) {
    case Type::kBool:
      return boolean ? "true" : "false";
    case Type::kInt:
      return std::to_string(integer);
    case Type::kDouble:
      return formatNumber(number);
    case Type::kString:
      return "string \"" + text + "\"";
    case Type::kList:
      return "a list";
    case Type::kDictionary:
      return "a dictionary";
    case Type::kOther:
      break;
  }
  return "a value of an unsupported type";
}

std::string constraintError(const std::string& prefix, const std::string& path, const std::string& relation,
                            const std::string& other_path, const ParameterValue& other,
                            const ParameterValue& got) {
  return "parameter " + prefix + path + " must " + relation + " " + prefix + other_path + " (" +
         other.describe() + "), got " + got.describe();
}

bool SubtreeSource::find(const std::string& path, ParameterValue* value) const {
  return source_.find(prefix_ + path, value);
}

std::vector<std::string> SubtreeSource::leafPaths() const {
  std::vector<std::string> paths;
  for (const std::string& path : source_.leafPaths()) {
    if (startsWith(path, prefix_)) paths.push_back(path.substr(prefix_.size()));
  }
  return paths;
}

void ParameterTree::erase(const std::string& path) {
  values_.erase(path);
  const std::string below = path + "/";
  for (auto it = values_.lower_bound(below); it != values_.end() && startsWith(it->first, below);) {
    it = values_.erase(it);
  }
  for (auto slash = path.rfind('/'); slash != std::string::npos; slash = path.rfind('/', slash - 1)) {
    values_.erase(path.substr(0, slash));  // an ancestor's value gives way to its children
    if (slash == 0) break;
  }
}

void ParameterTree::set(const std::string& path, const ParameterValue& value) {
  erase(path);
  values_[path] = value;
}

void ParameterTree::setTree(const std::string& path, const ParameterTree& tree) {
  erase(path);
  if (tree.values_.empty()) values_[path] = ParameterValue::ofType(ParameterValue::Type::kDictionary);
  for (const auto& entry : tree.values_) values_[path + "/" + entry.first] = entry.second;
}

ParameterTree ParameterTree::subtree(const std::string& path) const {
  ParameterTree tree;
  const std::string below = path + "/";
  for (auto it = values_.lower_bound(below); it != values_.end() && startsWith(it->first, below); ++it) {
    tree.values_[it->first.substr(below.size())] = it->second;
  }
  return tree;
}

bool ParameterTree::find(const std::string& path, ParameterValue* value) const {
  const auto exact = values_.find(path);
  if (exact != values_.end()) {
    *value = exact->second;
    return true;
  }
  const std::string below = path + "/";
  const auto child = values_.lower_bound(below);
  if (child == values_.end() || !startsWith(child->first, below)) return false;
  *value = ParameterValue::ofType(ParameterValue::Type::kDictionary);
  return true;
}

std::vector<std::string> ParameterTree::leafPaths() const {
  std::vector<std::string> paths;
  for (const auto& entry : values_) {
    if (entry.second.type != ParameterValue::Type::kDictionary) paths.push_back(entry.first);
  }
  return paths;
}

OptionReader::OptionReader(const ParameterSource& source, std::string display_prefix)
    : source_(source), prefix_(std::move(display_prefix)) {}

bool OptionReader::find(const std::string& path, ParameterValue* value) {
  known_.insert(path);
  return !failed() && source_.find(path, value);
}

void OptionReader::fail(const std::string& path, const std::string& requirement, const std::string& got) {
  if (!failed()) error_ = "parameter " + prefix_ + path + " must be " + requirement + ", got " + got;
}

void OptionReader::number(const std::string& path, double* out, double lo, double hi, bool positive,
                          bool allow_inf) {
  ParameterValue value;
  if (!find(path, &value)) return;
  double number = 0.0;
  const bool is_number = numberOf(value, &number);
  const bool inf_ok = allow_inf && std::isinf(number) && number > 0.0;
  if (!is_number || std::isnan(number) || (!std::isfinite(number) && !inf_ok) || number < lo || number > hi ||
      (positive && number <= 0.0)) {
    fail(path, numberRequirement(lo, hi, positive, allow_inf), value.describe());
    return;
  }
  *out = number;
}

void OptionReader::integer(const std::string& path, int* out, int lo, int hi) {
  ParameterValue value;
  if (!find(path, &value)) return;
  if (value.type != ParameterValue::Type::kInt || value.integer < lo || value.integer > hi) {
    std::string requirement;
    if (lo == 1 && hi == std::numeric_limits<int>::max()) {
      requirement = "a positive integer";
    } else if (lo == 0 && hi == std::numeric_limits<int>::max()) {
      requirement = "a non-negative integer";
    } else {
      requirement = "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    }
    fail(path, requirement, value.describe());
    return;
  }
  *out = value.integer;
}

void OptionReader::boolean(const std::string& path, bool* out) {
  ParameterValue value;
  if (!find(path, &value)) return;
  if (value.type != ParameterValue::Type::kBool) {
    fail(path, "true or false", value.describe());
    return;
  }
  *out = value.boolean;
}

bool OptionReader::text(const std::string& path, std::string* out, const TextCheck& check) {
  ParameterValue value;
  if (!find(path, &value)) return false;
  if (value.type != ParameterValue::Type::kString || value.text.empty()) {
    fail(path, "a non-empty string", value.describe());
    return false;
  }
  std::string text = value.text;
  const std::string requirement = check ? check(&text) : std::string();
  if (!requirement.empty()) {
    fail(path, requirement, value.describe());
    return false;
  }
  *out = text;
  return true;
}

void OptionReader::autoOrNumber(const std::string& path, bool* automatic, double* out, double limit,
                                const std::string& unit) {
  ParameterValue value;
  if (!find(path, &value)) return;
  if (value.type == ParameterValue::Type::kString && value.text == "auto") {
    *automatic = true;
    *out = 0.0;
    return;
  }
  double number = 0.0;
  if (!numberOf(value, &number) || !(std::abs(number) <= limit)) {
    fail(path,
         "auto or a number of " + unit + " in [-" + formatNumber(limit) + ", " + formatNumber(limit) + "]",
         value.describe());
    return;
  }
  *automatic = false;
  *out = number;
}

void OptionReader::removed(const std::string& path, const std::string& why) {
  ParameterValue value;
  if (!find(path, &value)) return;
  error_ = "parameter " + prefix_ + path + " (" + value.describe() + ") was removed: " + why;
}

std::vector<std::string> OptionReader::unknownPaths(const std::set<std::string>& skipped_top_level) const {
  std::vector<std::string> unknown;
  for (const std::string& path : source_.leafPaths()) {
    if (skipped_top_level.count(path.substr(0, path.find('/'))) != 0) continue;
    bool known = false;  // the path or a dictionary holding it was read
    for (auto end = path.find('/'); !known; end = path.find('/', end + 1)) {
      known = known_.count(path.substr(0, end)) != 0;
      if (end == std::string::npos) break;
    }
    if (!known) unknown.push_back(prefix_ + path);
  }
  return unknown;
}

}  // namespace hglasm
