#include "hglasm_odometry/tools/yaml_parameters.h"

#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <regex>
#include <stdexcept>

namespace hglasm_odometry {
namespace {

using hglasm::ParameterTree;
using hglasm::ParameterValue;

// PyYAML's resolvers (yaml/resolver.py) for the forms read here; a float needs a dot (1e-3 is a string).
const std::regex kTrue("yes|Yes|YES|true|True|TRUE|on|On|ON");
const std::regex kFalse("no|No|NO|false|False|FALSE|off|Off|OFF");
const std::regex kInt("[-+]?(0|[1-9][0-9]*)");
const std::regex kFloat("[-+]?[0-9]+\\.[0-9]*([eE][-+][0-9]+)?|\\.[0-9]+([eE][-+][0-9]+)?");
const std::regex kSpecial("[-+]?\\.(inf|Inf|INF)|\\.(nan|NaN|NAN)");
// rosparam's angles, of a plain number here: deg(80) = 80 * pi / 180, rad(1.5) = 1.5.
const std::regex kAngle("(deg|rad)\\( *([-+]?([0-9]+\\.?[0-9]*|\\.[0-9]+)([eE][-+]?[0-9]+)?) *\\)");
// Other numbers, dates, merge keys and angles of YAML 1.1 / rosparam: refused, not read differently.
const std::regex kRefused("[-+]?\\.?[0-9].*|<<|=|(deg|rad)\\(.*");

/// The first problem, with its line and key (the caller adds the file).
struct Failure : std::runtime_error {
  Failure(const YAML::Node& node, const std::string& key, const std::string& message)
      : std::runtime_error((node.Mark().is_null() ? "" : ":" + std::to_string(node.Mark().line + 1)) + ": " +
                           (key.empty() ? "" : key + ": ") + message) {}
};

/// A scalar typed as rosparam types it: quoted and block scalars are strings, plain ones are resolved.
ParameterValue scalarOf(const YAML::Node& node, const std::string& key) {
  const std::string& text = node.Scalar();
  if (node.Tag() == "!") return ParameterValue::ofString(text);
  if (node.Tag() != "?") throw Failure(node, key, "unsupported tag '" + node.Tag() + "'");
  std::smatch angle;
  if (std::regex_match(text, kTrue)) return ParameterValue::ofBool(true);
  if (std::regex_match(text, kFalse)) return ParameterValue::ofBool(false);
  if (std::regex_match(text, kFloat)) return ParameterValue::ofDouble(std::strtod(text.c_str(), nullptr));
  if (std::regex_match(text, kSpecial)) {
    const double inf = std::numeric_limits<double>::infinity();
    return ParameterValue::ofDouble(text.find_first_of("aA") != std::string::npos ? std::nan("")
                                    : text[0] == '-'                              ? -inf
                                                                                  : inf);
  }
  if (std::regex_match(text, kInt)) {
    errno = 0;
    const long long value = std::strtoll(text.c_str(), nullptr, 10);
    if (errno == ERANGE || value < INT_MIN || value > INT_MAX) {
      throw Failure(node, key, "'" + text + "' is not a 32-bit int (the parameter server's)");
    }
    return ParameterValue::ofInt(static_cast<int>(value));
  }
  if (std::regex_match(text, angle, kAngle)) {
    const double value = std::strtod(angle[2].str().c_str(), nullptr);
    return ParameterValue::ofDouble(angle[1] == "deg" ? value * M_PI / 180.0 : value);
  }
  if (std::regex_match(text, kRefused)) {
    throw Failure(node, key,
                  "'" + text +
                      "' is not read here as rosparam reads it: quote a string; write numbers as "
                      "decimal ints, floats with a dot (1.0e-3, not 1e-3), deg(N) or rad(N); no merge keys");
  }
  return ParameterValue::ofString(text);
}

ParameterValue valueOf(const YAML::Node& node, const std::string& key);

/// A mapping's parameters by path below it (`key`: its own path, for messages).
ParameterTree treeOf(const YAML::Node& node, const std::string& key) {
  ParameterTree tree;
  for (const auto& entry : node) {
    const std::string name = entry.first.IsScalar() ? entry.first.Scalar() : "?";
    if (key.empty() && name == "_ns") continue;  // rosparam's namespace key
    const std::string path = key.empty() ? name : key + "/" + name;
    if (!entry.first.IsScalar() || scalarOf(entry.first, path).type != ParameterValue::Type::kString) {
      throw Failure(entry.first, path, "a key must be a string: quote it");
    }
    if (entry.second.IsMap()) {  // a repeated key replaces the earlier value
      tree.setTree(name, treeOf(entry.second, path));
    } else {
      tree.set(name, valueOf(entry.second, path));
    }
  }
  return tree;
}

/// A value that is not a mapping's own entry: a list keeps its items; a mapping in a list is checked, its
/// type kept (no option is a list).
ParameterValue valueOf(const YAML::Node& node, const std::string& key) {
  if (node.IsScalar()) return scalarOf(node, key);
  if (node.IsMap()) {
    treeOf(node, key);
    return ParameterValue::ofType(ParameterValue::Type::kDictionary);
  }
  if (!node.IsSequence()) {
    throw Failure(node, key, "a null value (~, null or nothing): the parameter server cannot hold it");
  }
  ParameterValue list = ParameterValue::ofType(ParameterValue::Type::kList);
  for (std::size_t i = 0; i < node.size(); ++i) {
    list.items.push_back(valueOf(node[i], key + "[" + std::to_string(i) + "]"));
  }
  return list;
}

}  // namespace

bool loadYamlParameters(const std::string& path, ParameterTree* tree, std::string* error) {
  if (!std::ifstream(path)) {
    *error = "cannot read " + path;
    return false;
  }
  try {
    const YAML::Node root = YAML::LoadFile(path);
    if (!root.IsNull() && !root.IsMap()) {
      *error = path + " does not hold a dictionary of parameters";
      return false;
    }
    *tree = root.IsMap() ? treeOf(root, "") : ParameterTree();  // an empty file: no parameters
    return true;
  } catch (const YAML::Exception& exception) {
    *error = path + ":" + std::to_string(exception.mark.line + 1) + ":" +
             std::to_string(exception.mark.column + 1) + ": " + exception.msg;
  } catch (const Failure& failure) {
    *error = path + failure.what();
  }
  return false;
}

}  // namespace hglasm_odometry
