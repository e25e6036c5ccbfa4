// YAML -> XmlRpc as rosparam does it: yaml-cpp parses, PyYAML's YAML 1.1 resolution and constructors
// (yaml/resolver.py, yaml/constructor.py) and rosparam's angle constructors (rosparam/__init__.py) type
// the scalars. Each rule below names the Python it mirrors.
#include "hglasm_odometry/tools/yaml_parameters.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <regex>
#include <sstream>
#include <utility>
#include <vector>

namespace hglasm_odometry {

namespace {

using XmlRpc::XmlRpcValue;

const std::string kYamlTag = "tag:yaml.org,2002:";
const char kWhitespace[] = " \t\n\r\f\v";
// A decimal number as Python's float() and literals read it: 2, 1_000, 1.5, .5, 5., 1e-3.
const std::string kPythonDecimal =
    "(?:[0-9](?:_?[0-9])*(?:\\.(?:[0-9](?:_?[0-9])*)?)?|\\.[0-9](?:_?[0-9])*)(?:[eE][-+]?[0-9](?:_?[0-9])*)?";

enum class ScalarType { kString, kBool, kInt, kFloat, kNull, kDegrees, kRadians, kTimestamp, kMerge, kValue };

/// PyYAML's implicit resolvers (Resolver.add_implicit_resolver) and rosparam's deg()/rad(), for plain
/// scalars. The regular expressions are PyYAML's, verbatim but for the verbose-mode spaces.
ScalarType resolvePlain(const std::string& text) {
  static const std::vector<std::pair<ScalarType, std::regex>> resolvers = {
      {ScalarType::kBool,
       std::regex("^(?:yes|Yes|YES|no|No|NO|true|True|TRUE|false|False|FALSE|on|On|ON|off|Off|OFF)$")},
      {ScalarType::kFloat,
       std::regex(
           "^(?:[-+]?(?:[0-9][0-9_]*)\\.[0-9_]*(?:[eE][-+][0-9]+)?|\\.[0-9][0-9_]*(?:[eE][-+][0-9]+)?"
           "|[-+]?[0-9][0-9_]*(?::[0-5]?[0-9])+\\.[0-9_]*|[-+]?\\.(?:inf|Inf|INF)|\\.(?:nan|NaN|NAN))$")},
      {ScalarType::kInt, std::regex("^(?:[-+]?0b[0-1_]+|[-+]?0[0-7_]+|[-+]?(?:0|[1-9][0-9_]*)"
                                    "|[-+]?0x[0-9a-fA-F_]+|[-+]?[1-9][0-9_]*(?::[0-5]?[0-9])+)$")},
      {ScalarType::kMerge, std::regex("^(?:<<)$")},
      {ScalarType::kNull, std::regex("^(?:~|null|Null|NULL|)$")},
      {ScalarType::kTimestamp,
       std::regex(
           "^(?:[0-9][0-9][0-9][0-9]-[0-9][0-9]-[0-9][0-9]|[0-9][0-9][0-9][0-9]-[0-9][0-9]?-[0-9][0-9]?"
           "(?:[Tt]|[ \\t]+)[0-9][0-9]?:[0-9][0-9]:[0-9][0-9](?:\\.[0-9]*)?"
           "(?:[ \\t]*(?:Z|[-+][0-9][0-9]?(?::[0-9][0-9])?))?)$")},
      {ScalarType::kValue, std::regex("^(?:=)$")},
      {ScalarType::kDegrees, std::regex("^deg\\([^\\)]*\\)$")},
      {ScalarType::kRadians, std::regex("^rad\\([^\\)]*\\)$")},
  };
  for (const auto& resolver : resolvers) {
    if (std::regex_match(text, resolver.second)) return resolver.first;
  }
  return ScalarType::kString;
}

std::string without(const std::string& text, char removed) {
  std::string result;
  std::copy_if(text.begin(), text.end(), std::back_inserter(result),
               [removed](char c) { return c != removed; });
  return result;
}

std::string trim(const std::string& text) {
  const auto first = text.find_first_not_of(kWhitespace);
  return first == std::string::npos ? std::string()
                                    : text.substr(first, text.find_last_not_of(kWhitespace) - first + 1);
}

std::string lowercase(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

/// Python's float(text) for decimal text: surrounding whitespace, underscores between digits,
/// inf / infinity / nan in any case.
bool parsePythonFloat(const std::string& raw, double* value) {
  const std::string text = trim(raw);
  if (text.empty()) return false;
  const std::string lower = lowercase(text);
  const std::size_t unsigned_at = lower[0] == '-' || lower[0] == '+' ? 1 : 0;
  const std::string word = lower.substr(unsigned_at);
  const double sign = lower[0] == '-' ? -1.0 : 1.0;
  if (word == "inf" || word == "infinity") {
    *value = sign * std::numeric_limits<double>::infinity();
    return true;
  }
  if (word == "nan") {
    *value = std::numeric_limits<double>::quiet_NaN();
    return true;
  }
  static const std::regex decimal("^[-+]?" + kPythonDecimal + "$");
  if (!std::regex_match(text, decimal)) return false;
  *value = std::strtod(without(text, '_').c_str(), nullptr);
  return true;
}

/// SafeConstructor.construct_yaml_int; false beyond XML-RPC's 32-bit ints (xmlrpc.client refuses them).
bool constructInt(const std::string& scalar, int* value) {
  std::string text = without(scalar, '_');
  const long long sign = text[0] == '-' ? -1 : 1;
  if (text[0] == '-' || text[0] == '+') text.erase(0, 1);
  int base = 10;
  std::vector<std::string> digits = {text};
  if (text.rfind("0b", 0) == 0) {
    base = 2, digits = {text.substr(2)};
  } else if (text.rfind("0x", 0) == 0) {
    base = 16, digits = {text.substr(2)};
  } else if (text.size() > 1 && text[0] == '0') {
    base = 8;
  } else if (text.find(':') != std::string::npos) {
    digits.clear();  // sexagesimal: 1:30 = 90
    std::stringstream parts(text);
    for (std::string part; std::getline(parts, part, ':');) digits.push_back(part);
  }
  long long total = 0;
  for (const std::string& part : digits) {
    if (part.empty()) return false;
    char* end = nullptr;
    errno = 0;
    const long long parsed = std::strtoll(part.c_str(), &end, base);
    if (*end != '\0' || errno == ERANGE || parsed > (1LL << 32)) return false;
    total = total * (digits.size() > 1 ? 60 : 1) + parsed;
    if (total > (1LL << 32)) return false;  // far beyond 32 bits already: stop before overflowing
  }
  total *= sign;
  if (total < std::numeric_limits<int>::min() || total > std::numeric_limits<int>::max()) return false;
  *value = static_cast<int>(total);
  return true;
}

/// SafeConstructor.construct_yaml_float.
bool constructFloat(const std::string& scalar, double* value) {
  std::string text = lowercase(without(scalar, '_'));
  const double sign = text[0] == '-' ? -1.0 : 1.0;
  if (text[0] == '-' || text[0] == '+') text.erase(0, 1);
  if (text == ".inf") {
    *value = sign * std::numeric_limits<double>::infinity();
    return true;
  }
  if (text == ".nan") {
    *value = std::numeric_limits<double>::quiet_NaN();
    return true;
  }
  if (text.find(':') == std::string::npos) {
    double parsed = 0.0;
    if (!parsePythonFloat(text, &parsed)) return false;
    *value = sign * parsed;
    return true;
  }
  std::vector<double> digits;  // sexagesimal: 1:30.5 = 90.5
  std::stringstream parts(text);
  for (std::string part; std::getline(parts, part, ':');) {
    digits.push_back(0.0);
    if (!parsePythonFloat(part, &digits.back())) return false;
  }
  double total = 0.0, base = 1.0;
  for (auto digit = digits.rbegin(); digit != digits.rend(); ++digit, base *= 60.0) total += *digit * base;
  *value = sign * total;
  return true;
}

/// A number of Python's arithmetic: an exact int or a float.
struct PyNumber {
  bool is_int = true;
  long long integer = 0;
  double real = 0.0;
  double asDouble() const { return is_int ? static_cast<double>(integer) : real; }
};

/// The Python expressions rosparam's rad(...) evaluates (numbers, pi, + - * / **, parentheses) with
/// Python's precedence and int/float rules, so rad(pi/2) is bit for bit Python's math.pi / 2.
class AngleExpression {
 public:
  explicit AngleExpression(std::string text) : text_(std::move(text)) {}

  bool evaluate(double* value) {
    PyNumber result;
    if (!sum(&result)) return false;
    skipSpaces();
    if (position_ != text_.size()) return false;
    *value = result.asDouble();
    return true;
  }

 private:
  void skipSpaces() {
    while (position_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[position_])))
      ++position_;
  }
  bool accept(const char* token) {
    skipSpaces();
    const std::string expected = token;
    if (text_.compare(position_, expected.size(), expected) != 0) return false;
    if (expected == "*" && text_.compare(position_, 2, "**") == 0) return false;
    position_ += expected.size();
    return true;
  }

  /// a op b into *out (which may be a): ints stay exact but for true division, as in Python.
  static bool apply(char op, PyNumber a, PyNumber b, PyNumber* out) {
    if (op == '/' && b.asDouble() == 0.0) return false;  // ZeroDivisionError
    if (a.is_int && b.is_int && op != '/') {
      out->is_int = true;
      if (op == '+') return !__builtin_add_overflow(a.integer, b.integer, &out->integer);
      if (op == '-') return !__builtin_sub_overflow(a.integer, b.integer, &out->integer);
      return !__builtin_mul_overflow(a.integer, b.integer, &out->integer);
    }
    const double x = a.asDouble(), y = b.asDouble();
    out->is_int = false;
    out->real = op == '+' ? x + y : op == '-' ? x - y : op == '*' ? x * y : x / y;
    return true;
  }

  bool sum(PyNumber* value) {
    if (!product(value)) return false;
    for (char op; (op = accept("+") ? '+' : accept("-") ? '-' : 0);) {
      PyNumber right;
      if (!product(&right) || !apply(op, *value, right, value)) return false;
    }
    return true;
  }
  bool product(PyNumber* value) {
    if (!factor(value)) return false;
    for (char op; (op = accept("*") ? '*' : accept("/") ? '/' : 0);) {
      PyNumber right;
      if (!factor(&right) || !apply(op, *value, right, value)) return false;
    }
    return true;
  }
  bool factor(PyNumber* value) {
    if (accept("+")) return factor(value);
    if (!accept("-")) return power(value);
    if (!factor(value)) return false;
    value->real = -value->real;  // a sign flip, as Python's: -0.0 stays negative
    return !value->is_int || !__builtin_mul_overflow(value->integer, -1LL, &value->integer);
  }
  bool power(PyNumber* value) {
    if (!atom(value)) return false;
    if (!accept("**")) return true;
    PyNumber exponent;
    if (!factor(&exponent)) return false;
    if (value->is_int && exponent.is_int && exponent.integer >= 0) {
      const long long base = value->integer;
      long long result = 1;
      // |base| >= 2 overflows within 63 steps; 0, 1 and -1 repeat within 2.
      for (long long i = 0; i < std::min(exponent.integer, 64LL + exponent.integer % 2); ++i) {
        if (__builtin_mul_overflow(result, base, &result)) return false;
      }
      value->integer = result;
      return true;
    }
    const double base = value->asDouble(), power = exponent.asDouble();
    value->is_int = false;
    value->real = std::pow(base, power);
    return !std::isnan(value->real) || std::isnan(base) || std::isnan(power);  // Python: complex
  }
  bool atom(PyNumber* value) {
    if (accept("(")) return sum(value) && accept(")");
    skipSpaces();
    if (text_.compare(position_, 2, "pi") == 0) {
      position_ += 2;
      value->is_int = false;
      value->real = M_PI;
      return true;
    }
    static const std::regex number("^" + kPythonDecimal);
    std::smatch match;
    const std::string rest = text_.substr(position_);
    if (!std::regex_search(rest, match, number)) return false;
    position_ += static_cast<std::size_t>(match.length(0));
    const std::string literal = without(match.str(0), '_');
    value->is_int = literal.find_first_of(".eE") == std::string::npos;
    if (!value->is_int) {
      value->real = std::strtod(literal.c_str(), nullptr);
      return true;
    }
    if (literal.size() > 1 && literal[0] == '0') return false;  // 007 is a syntax error in Python 3
    errno = 0;
    value->integer = std::strtoll(literal.c_str(), nullptr, 10);
    return errno != ERANGE;
  }

  std::string text_;
  std::size_t position_ = 0;
};

/// rosparam's construct_angle_degrees: float(inner) * math.pi / 180.0.
bool constructDegrees(const std::string& scalar, double* value) {
  std::string text = scalar;
  if (text.rfind("deg(", 0) == 0) {
    text = trim(text);
    text = text.size() >= 5 ? text.substr(4, text.size() - 5) : std::string();
  }
  if (!parsePythonFloat(text, value)) return false;
  *value = *value * M_PI / 180.0;
  return true;
}

/// rosparam's construct_angle_radians: float(eval(inner)) with pi.
bool constructRadians(const std::string& scalar, double* value) {
  std::string text = trim(scalar);
  if (text.rfind("rad(", 0) == 0) text = text.substr(4, text.size() - 5);
  return AngleExpression(text).evaluate(value);
}

/// Converts yaml-cpp nodes, naming the source and line of the first problem.
class Converter {
 public:
  Converter(std::string source, std::string* error) : source_(std::move(source)), error_(error) {}

  bool convert(const YAML::Node& node, XmlRpcValue* value) {
    switch (node.Type()) {
      case YAML::NodeType::Map:
        return convertMap(node, value);
      case YAML::NodeType::Sequence:
        value->setSize(static_cast<int>(node.size()));
        for (std::size_t i = 0; i < node.size(); ++i) {
          XmlRpcValue element;
          if (!convert(node[i], &element)) return false;
          (*value)[static_cast<int>(i)] = element;
        }
        return true;
      case YAML::NodeType::Scalar:
        return convertScalar(node, value);
      case YAML::NodeType::Null:
        if (node.Tag() == kYamlTag + "str") {
          *value = std::string();
          return true;
        }
        return fail(node, "a null value (~, null or nothing): the parameter server cannot hold it");
      case YAML::NodeType::Undefined:
        break;
    }
    return fail(node, "an undefined node");
  }

  bool fail(const YAML::Node& node, const std::string& message) {
    const YAML::Mark mark = node.Mark();
    *error_ = source_ + (mark.is_null() ? "" : ":" + std::to_string(mark.line + 1)) + ": " + message;
    return false;
  }

 private:
  /// The type rosparam gives a scalar: by its tag, or resolved when plain (untagged, unquoted).
  bool typeOf(const YAML::Node& node, ScalarType* type) {
    const std::string& tag = node.Tag();
    static const std::vector<std::pair<std::string, ScalarType>> tags = {
        {"!", ScalarType::kString},
        {kYamlTag + "str", ScalarType::kString},
        {kYamlTag + "int", ScalarType::kInt},
        {kYamlTag + "float", ScalarType::kFloat},
        {kYamlTag + "bool", ScalarType::kBool},
        {"!degrees", ScalarType::kDegrees},
        {"!radians", ScalarType::kRadians}};
    if (tag == "?") {
      *type = resolvePlain(node.Scalar());
      return true;
    }
    for (const auto& entry : tags) {
      if (entry.first == tag) {
        *type = entry.second;
        return true;
      }
    }
    return fail(node, "unsupported tag '" + tag + "'");
  }

  bool convertScalar(const YAML::Node& node, XmlRpcValue* value) {
    ScalarType type = ScalarType::kString;
    if (!typeOf(node, &type)) return false;
    const std::string& text = node.Scalar();
    int integer = 0;
    double real = 0.0;
    switch (type) {
      case ScalarType::kString:
        *value = text;
        return true;
      case ScalarType::kBool:
        return constructBool(node, value);
      case ScalarType::kInt:
        if (!constructInt(text, &integer)) return fail(node, "'" + text + "' is not a 32-bit integer");
        *value = integer;
        return true;
      case ScalarType::kFloat:
        if (!constructFloat(text, &real)) return fail(node, "'" + text + "' is not a number");
        *value = real;
        return true;
      case ScalarType::kDegrees:
        if (!constructDegrees(text, &real)) return fail(node, "invalid degree value '" + text + "'");
        *value = real;
        return true;
      case ScalarType::kRadians:
        if (!constructRadians(text, &real)) {
          return fail(node,
                      "invalid radian expression '" + text + "' (numbers, pi, + - * / ** and parentheses)");
        }
        *value = real;
        return true;
      case ScalarType::kNull:
        return fail(node, "a null value (~, null or nothing): the parameter server cannot hold it");
      case ScalarType::kTimestamp:
        return fail(node, "'" + text + "' is a YAML timestamp: quote it to make it a string");
      case ScalarType::kMerge:
      case ScalarType::kValue:
        break;
    }
    return fail(node, "'" + text + "' cannot be a value");
  }

  /// SafeConstructor.construct_yaml_bool.
  bool constructBool(const YAML::Node& node, XmlRpcValue* value) {
    const std::string word = lowercase(node.Scalar());
    if (word == "yes" || word == "true" || word == "on") {
      *value = true;
    } else if (word == "no" || word == "false" || word == "off") {
      *value = false;
    } else {
      return fail(node, "'" + node.Scalar() + "' is not a bool");
    }
    return true;
  }

  /// PyYAML's flatten_mapping: the entries merged in with `<<` come first, so the mapping's own keys
  /// override them; of a list of merged mappings, the earlier ones override the later.
  bool entries(const YAML::Node& map, std::vector<std::pair<YAML::Node, YAML::Node>>* result) {
    std::vector<std::pair<YAML::Node, YAML::Node>> own, merged;
    for (const auto& entry : map) {
      const bool merge = entry.first.IsScalar() && entry.first.Tag() == "?" && entry.first.Scalar() == "<<";
      if (!merge) {
        own.emplace_back(entry.first, entry.second);
        continue;
      }
      std::vector<YAML::Node> sources;
      if (entry.second.IsMap()) sources.push_back(entry.second);
      if (entry.second.IsSequence()) {
        for (const YAML::Node& item : entry.second) sources.push_back(item);
      }
      if (sources.empty()) {
        return fail(entry.second, "a merge key (<<) needs a mapping or a list of mappings");
      }
      // Last first. (No std::reverse: assigning a YAML::Node rewrites the node it refers to.)
      for (auto source = sources.rbegin(); source != sources.rend(); ++source) {
        if (!source->IsMap()) return fail(*source, "a merge key (<<) needs a mapping or a list of mappings");
        if (!entries(*source, &merged)) return false;
      }
    }
    result->insert(result->end(), merged.begin(), merged.end());
    result->insert(result->end(), own.begin(), own.end());
    return true;
  }

  bool convertMap(const YAML::Node& node, XmlRpcValue* value) {
    value->begin();  // an empty mapping is an empty struct
    std::vector<std::pair<YAML::Node, YAML::Node>> pairs;
    if (!entries(node, &pairs)) return false;
    for (const auto& pair : pairs) {
      const YAML::Node& key = pair.first;
      ScalarType type = ScalarType::kString;
      if (!key.IsScalar() || !typeOf(key, &type) ||
          (type != ScalarType::kString && type != ScalarType::kValue)) {
        const std::string shown = key.IsScalar() ? "'" + key.Scalar() + "'" : "a non-scalar";
        return fail(key, "key " + shown + " is not a string (quote it): the parameter server cannot hold it");
      }
      XmlRpcValue converted;  // fresh: a repeated key replaces the earlier value, as in PyYAML
      if (!convert(pair.second, &converted)) return false;
      (*value)[key.Scalar()] = converted;
    }
    return true;
  }

  std::string source_;
  std::string* error_;
};

}  // namespace

bool parseYamlParameters(const std::string& text, const std::string& source, XmlRpcValue* value,
                         std::string* error) {
  std::vector<YAML::Node> documents;
  try {
    documents = YAML::LoadAll(text);
  } catch (const YAML::Exception& exception) {
    *error = source + ":" + std::to_string(exception.mark.line + 1) + ":" +
             std::to_string(exception.mark.column + 1) + ": " + exception.msg;
    return false;
  }
  *value = XmlRpcValue();
  if (documents.empty()) {
    value->begin();  // an empty file: no parameters
    return true;
  }
  return Converter(source, error).convert(documents.front(), value);
}

bool loadYamlParameters(const std::string& path, XmlRpcValue* value, std::string* error) {
  std::ifstream file(path);
  if (!file) {
    *error = "cannot read " + path;
    return false;
  }
  std::stringstream text;
  text << file.rdbuf();
  XmlRpcValue loaded;
  if (!parseYamlParameters(text.str(), path, &loaded, error)) return false;
  if (loaded.getType() != XmlRpcValue::TypeStruct) {
    *error = path + " does not hold a dictionary of parameters";
    return false;
  }
  *value = XmlRpcValue();
  value->begin();
  for (auto& entry : loaded) {
    if (entry.first != "_ns") (*value)[entry.first] = entry.second;
  }
  return true;
}

}  // namespace hglasm_odometry
