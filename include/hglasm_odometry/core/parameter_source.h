// Options read from, and written to, a tree of named parameters ("genetic/population"), without ROS: the
// ROS parameter server and YAML files are two implementations of ParameterSource (src/ros, src/tools).
// Each module declares its options' parameters beside its options struct as
//   template <typename Visitor> void visitOptions(Visitor& visitor, XOptions* options);
// calling the visitor's number/integer/boolean/... for each field, so one list serves reading (OptionReader:
// validated, the first error wins) and writing (OptionWriter). The defaults are the structs' initialisers.
#pragma once

#include <functional>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace hglasm {

/// One parameter's value, typed as the parameter server types it.
struct ParameterValue {
  enum class Type { kBool, kInt, kDouble, kString, kDictionary, kList, kOther };
  Type type = Type::kOther;
  bool boolean = false;
  int integer = 0;
  double number = 0.0;
  std::string text;
  std::vector<ParameterValue> items;  ///< of a list

  static ParameterValue ofBool(bool value);
  static ParameterValue ofInt(int value);
  static ParameterValue ofDouble(double value);
  static ParameterValue ofString(std::string value);
  static ParameterValue ofType(Type type);
  /// How it appears in an error message: "5", "-0.3", "string \"abc\"", "a list", "a dictionary".
  std::string describe() const;
};

/// A tree of parameters addressed by paths "a/b/c" relative to its root.
class ParameterSource {
 public:
  virtual ~ParameterSource() = default;
  /// The value at `path` (a dictionary if it has children); false if absent.
  virtual bool find(const std::string& path, ParameterValue* value) const = 0;
  /// The paths of every value that is not a dictionary, in order.
  virtual std::vector<std::string> leafPaths() const = 0;
};

/// The parameters of `source` under `prefix` ("presets/small/"), as a tree of their own.
class SubtreeSource : public ParameterSource {
 public:
  SubtreeSource(const ParameterSource& source, std::string prefix)
      : source_(source), prefix_(std::move(prefix)) {}
  bool find(const std::string& path, ParameterValue* value) const override;
  std::vector<std::string> leafPaths() const override;

 private:
  const ParameterSource& source_;
  std::string prefix_;
};

/// Parameters in memory: what OptionWriter writes and a YAML file is read into.
class ParameterTree : public ParameterSource {
 public:
  /// Sets the value at `path`, replacing whatever was at, below or above it (an empty dictionary is a
  /// value of type kDictionary).
  void set(const std::string& path, const ParameterValue& value);
  /// Every parameter of `tree` under `path` (replacing what was there).
  void setTree(const std::string& path, const ParameterTree& tree);
  /// The parameters below `path`, by their paths relative to it.
  ParameterTree subtree(const std::string& path) const;
  bool find(const std::string& path, ParameterValue* value) const override;
  std::vector<std::string> leafPaths() const override;
  /// Every value by path, empty dictionaries included.
  const std::map<std::string, ParameterValue>& values() const { return values_; }

 private:
  void erase(const std::string& path);
  std::map<std::string, ParameterValue> values_;
};

/// "parameter ~genetic/elite_count must be less than ~genetic/population (100), got 100": a constraint
/// between two parameters (`relation`: "be less than", "not exceed", ...), checked once every layer is
/// applied.
std::string constraintError(const std::string& prefix, const std::string& path, const std::string& relation,
                            const std::string& other_path, const ParameterValue& other,
                            const ParameterValue& got);

constexpr double kInfinity = std::numeric_limits<double>::infinity();

/// The ranges both visitors share: the reader validates them, the writer ignores them.
template <typename Derived>
class OptionRanges {
 public:
  void positiveNumber(const std::string& path, double* value) {
    self().number(path, value, 0.0, kInfinity, true);
  }
  void nonNegativeNumber(const std::string& path, double* value) {
    self().number(path, value, 0.0, kInfinity);
  }
  void fraction(const std::string& path, double* value) { self().number(path, value, 0.0, 1.0); }
  void positiveInteger(const std::string& path, int* value) {
    self().integer(path, value, 1, std::numeric_limits<int>::max());
  }

 private:
  Derived& self() { return static_cast<Derived&>(*this); }
};

/// Checks a string once it is known to be non-empty: "" if valid (possibly rewriting it), else what it
/// must be ("a relative or absolute topic name").
using TextCheck = std::function<std::string(std::string*)>;

/// Typed, validating reads from one source. The first error wins; later reads are no-ops. Every path read
/// is remembered, so the keys never read can be reported as unknown.
class OptionReader : public OptionRanges<OptionReader> {
 public:
  /// `display_prefix` precedes the path in messages ("~", "~presets/small/").
  OptionReader(const ParameterSource& source, std::string display_prefix);
  bool failed() const { return !error_.empty(); }
  /// One line naming the parameter ("parameter ~genetic/population must be a positive integer, got -5").
  const std::string& error() const { return error_; }

  /// Finds `path`; false if absent or after an error. Marks the path as known either way.
  bool find(const std::string& path, ParameterValue* value);
  void fail(const std::string& path, const std::string& requirement, const std::string& got);

  /// A number (int or double) within [lo, hi]; `positive` excludes 0. Infinity only if `allow_inf`.
  void number(const std::string& path, double* out, double lo, double hi, bool positive = false,
              bool allow_inf = false);
  void integer(const std::string& path, int* out, int lo, int hi);
  void boolean(const std::string& path, bool* out);
  /// A non-empty string that passes `check` (if any); false if absent or invalid.
  bool text(const std::string& path, std::string* out, const TextCheck& check = nullptr);
  /// "auto", or a number of `unit` within [-limit, limit] (*automatic false).
  void autoOrNumber(const std::string& path, bool* automatic, double* out, double limit,
                    const std::string& unit);
  /// A parameter that was removed: set at all, it is an error saying so (`why`: what to do instead).
  void removed(const std::string& path, const std::string& why);

  /// Leaf paths present but never read (typos), with the display prefix, skipping the given top-level keys.
  std::vector<std::string> unknownPaths(const std::set<std::string>& skipped_top_level = {}) const;

 private:
  const ParameterSource& source_;
  std::string prefix_;
  std::string error_;
  std::set<std::string> known_;
};

/// Writes every option at its parameter path: what OptionReader reads back unchanged.
class OptionWriter : public OptionRanges<OptionWriter> {
 public:
  explicit OptionWriter(ParameterTree* tree) : tree_(tree) {}
  void number(const std::string& path, double* value, double, double, bool = false, bool = false) {
    tree_->set(path, ParameterValue::ofDouble(*value));
  }
  void integer(const std::string& path, int* value, int, int) {
    tree_->set(path, ParameterValue::ofInt(*value));
  }
  void boolean(const std::string& path, bool* value) { tree_->set(path, ParameterValue::ofBool(*value)); }
  bool text(const std::string& path, std::string* value, const TextCheck& = nullptr) {
    tree_->set(path, ParameterValue::ofString(*value));
    return true;
  }
  void autoOrNumber(const std::string& path, bool* automatic, double* value, double, const std::string&) {
    tree_->set(path, *automatic ? ParameterValue::ofString("auto") : ParameterValue::ofDouble(*value));
  }

 private:
  ParameterTree* tree_;
};

}  // namespace hglasm
