// The validating reader and the writer over an in-memory ParameterSource: the messages users see name the
// parameter, the first error wins, unknown keys are reported, and what is written reads back.
#include "hglasm_odometry/core/parameter_source.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "hglasm_odometry/core/odometry_tracker.h"

namespace {

using hglasm::OptionReader;
using hglasm::ParameterTree;
using hglasm::ParameterValue;
using Type = hglasm::ParameterValue::Type;

ParameterTree tree(const std::vector<std::pair<std::string, ParameterValue>>& values) {
  ParameterTree result;
  for (const auto& entry : values) result.set(entry.first, entry.second);
  return result;
}

TEST(ParameterTree, FindsLeavesAndTheDictionariesHoldingThem) {
  const ParameterTree params =
      tree({{"a/b/c", ParameterValue::ofInt(1)}, {"a/d", ParameterValue::ofBool(true)}});
  ParameterValue value;
  ASSERT_TRUE(params.find("a/b/c", &value));
  EXPECT_EQ(value.type, Type::kInt);
  ASSERT_TRUE(params.find("a/b", &value));
  EXPECT_EQ(value.type, Type::kDictionary);
  EXPECT_FALSE(params.find("a/b/x", &value));
  EXPECT_FALSE(params.find("a/b/c/d", &value));
  EXPECT_EQ(params.leafPaths(), (std::vector<std::string>{"a/b/c", "a/d"}));
}

TEST(ParameterTree, AValueReplacesWhatWasAtAboveAndBelowIt) {
  ParameterTree params = tree({{"a/b", ParameterValue::ofInt(1)}, {"a/c", ParameterValue::ofInt(2)}});
  params.set("a", ParameterValue::ofInt(3));
  EXPECT_EQ(params.leafPaths(), std::vector<std::string>{"a"});
  params.set("a/x/y", ParameterValue::ofInt(4));
  EXPECT_EQ(params.leafPaths(), std::vector<std::string>{"a/x/y"});
  params.setTree("a", ParameterTree());  // an empty dictionary
  ParameterValue value;
  ASSERT_TRUE(params.find("a", &value));
  EXPECT_EQ(value.type, Type::kDictionary);
  EXPECT_TRUE(params.leafPaths().empty());
}

TEST(ParameterTree, SubtreesAndSubtreeSourcesSeePathsRelativeToThem) {
  const ParameterTree params = tree({{"presets/small/genetic/runs", ParameterValue::ofInt(2)},
                                     {"presets/large/genetic/runs", ParameterValue::ofInt(3)},
                                     {"queue_size", ParameterValue::ofInt(5)}});
  const hglasm::SubtreeSource small(params, "presets/small/");
  ParameterValue value;
  ASSERT_TRUE(small.find("genetic/runs", &value));
  EXPECT_EQ(value.integer, 2);
  EXPECT_EQ(small.leafPaths(), std::vector<std::string>{"genetic/runs"});
  EXPECT_EQ(params.subtree("presets/large").leafPaths(), std::vector<std::string>{"genetic/runs"});
}

TEST(OptionReader, ReadsTypedValuesAndLeavesAbsentOnesAlone) {
  const ParameterTree params = tree({{"n", ParameterValue::ofInt(3)},
                                     {"x", ParameterValue::ofInt(2)},
                                     {"flag", ParameterValue::ofBool(true)},
                                     {"name", ParameterValue::ofString("/odom")}});
  OptionReader reader(params, "~");
  int n = 0;
  double x = 0.0, absent = 7.0;
  bool flag = false;
  std::string name;
  reader.positiveInteger("n", &n);
  reader.positiveNumber("x", &x);  // an int where a number is expected
  reader.nonNegativeNumber("absent", &absent);
  reader.boolean("flag", &flag);
  reader.text("name", &name, [](std::string* text) {
    text->erase(0, 1);
    return std::string();
  });
  EXPECT_FALSE(reader.failed()) << reader.error();
  EXPECT_EQ(n, 3);
  EXPECT_EQ(x, 2.0);
  EXPECT_EQ(absent, 7.0);
  EXPECT_TRUE(flag);
  EXPECT_EQ(name, "odom");
}

std::string errorOf(const ParameterValue& value, const std::function<void(OptionReader&)>& read) {
  const ParameterTree params = tree({{"genetic/population", value}});
  OptionReader reader(params, "~");
  read(reader);
  return reader.error();
}

TEST(OptionReader, TypeAndRangeErrorsNameTheParameterAndWhatWasGot) {
  int population = 0;
  double number = 0.0;
  bool flag = false;
  auto positive = [&](OptionReader& reader) { reader.positiveInteger("genetic/population", &population); };
  EXPECT_EQ(errorOf(ParameterValue::ofInt(-5), positive),
            "parameter ~genetic/population must be a positive integer, got -5");
  EXPECT_EQ(errorOf(ParameterValue::ofDouble(5.0), positive),
            "parameter ~genetic/population must be a positive integer, got 5");
  EXPECT_EQ(errorOf(ParameterValue::ofString("many"), positive),
            "parameter ~genetic/population must be a positive integer, got string \"many\"");
  EXPECT_EQ(errorOf(ParameterValue::ofType(Type::kList), positive),
            "parameter ~genetic/population must be a positive integer, got a list");
  EXPECT_EQ(errorOf(ParameterValue::ofInt(1),
                    [&](OptionReader& reader) { reader.integer("genetic/population", &population, 2, 100); }),
            "parameter ~genetic/population must be an integer in [2, 100], got 1");
  EXPECT_EQ(errorOf(ParameterValue::ofDouble(1.5),
                    [&](OptionReader& reader) { reader.fraction("genetic/population", &number); }),
            "parameter ~genetic/population must be a number in [0, 1], got 1.5");
  EXPECT_EQ(errorOf(ParameterValue::ofDouble(std::nan("")),
                    [&](OptionReader& reader) { reader.nonNegativeNumber("genetic/population", &number); }),
            "parameter ~genetic/population must be a non-negative number, got nan");
  EXPECT_EQ(errorOf(ParameterValue::ofDouble(hglasm::kInfinity),
                    [&](OptionReader& reader) { reader.positiveNumber("genetic/population", &number); }),
            "parameter ~genetic/population must be a positive number, got inf");
  EXPECT_EQ(errorOf(ParameterValue::ofInt(0),
                    [&](OptionReader& reader) { reader.boolean("genetic/population", &flag); }),
            "parameter ~genetic/population must be true or false, got 0");
  EXPECT_EQ(number, 0.0);  // a failed read leaves the option alone
}

TEST(OptionReader, InfinityOnlyWhereAllowed) {
  const ParameterTree params = tree({{"max_range", ParameterValue::ofDouble(hglasm::kInfinity)}});
  OptionReader reader(params, "~");
  double range = 0.0;
  reader.number("max_range", &range, 0.0, hglasm::kInfinity, true, true);
  EXPECT_FALSE(reader.failed()) << reader.error();
  EXPECT_TRUE(std::isinf(range));
}

TEST(OptionReader, TheFirstErrorWins) {
  const ParameterTree params = tree({{"a", ParameterValue::ofInt(-1)}, {"b", ParameterValue::ofString("x")}});
  OptionReader reader(params, "~presets/small/");
  int a = 0;
  bool b = false;
  reader.positiveInteger("a", &a);
  reader.boolean("b", &b);
  EXPECT_EQ(reader.error(), "parameter ~presets/small/a must be a positive integer, got -1");
}

TEST(OptionReader, AutoOrANumber) {
  const ParameterTree params = tree({{"auto", ParameterValue::ofString("auto")},
                                     {"fixed", ParameterValue::ofDouble(0.3)},
                                     {"far", ParameterValue::ofInt(11)}});
  OptionReader reader(params, "~");
  bool automatic = false;
  double offset = 1.0;
  reader.autoOrNumber("auto", &automatic, &offset, 10.0, "seconds");
  EXPECT_TRUE(automatic);
  EXPECT_EQ(offset, 0.0);
  reader.autoOrNumber("fixed", &automatic, &offset, 10.0, "seconds");
  EXPECT_FALSE(automatic);
  EXPECT_EQ(offset, 0.3);
  reader.autoOrNumber("far", &automatic, &offset, 10.0, "seconds");
  EXPECT_EQ(reader.error(), "parameter ~far must be auto or a number of seconds in [-10, 10], got 11");
}

TEST(OptionReader, TextChecksAndRemovedParameters) {
  const ParameterTree params =
      tree({{"topic", ParameterValue::ofString("~bad")}, {"empty", ParameterValue::ofString("")}});
  std::string text;
  OptionReader empty(params, "~");
  EXPECT_FALSE(empty.text("empty", &text));
  EXPECT_EQ(empty.error(), "parameter ~empty must be a non-empty string, got string \"\"");
  OptionReader checked(params, "~");
  EXPECT_FALSE(checked.text("topic", &text, [](std::string* topic) {
    return (*topic)[0] == '~' ? std::string("a relative or absolute topic name") : std::string();
  }));
  EXPECT_EQ(checked.error(),
            "parameter ~topic must be a relative or absolute topic name, got string \"~bad\"");
  OptionReader removed(params, "~");
  removed.removed("topic", "delete it");
  EXPECT_EQ(removed.error(), "parameter ~topic (string \"~bad\") was removed: delete it");
}

TEST(OptionReader, KeysNeverReadAreUnknownUnlessADictionaryHoldingThemWasRead) {
  const ParameterTree params = tree({{"genetic/populaton", ParameterValue::ofInt(30)},
                                     {"genetic/runs", ParameterValue::ofInt(2)},
                                     {"presets/custom/x", ParameterValue::ofInt(1)},
                                     {"skipped/y", ParameterValue::ofInt(1)}});
  OptionReader reader(params, "~");
  int runs = 0;
  reader.positiveInteger("genetic/runs", &runs);
  ParameterValue presets;
  reader.find("presets", &presets);
  EXPECT_EQ(reader.unknownPaths({"skipped"}), std::vector<std::string>{"~genetic/populaton"});
}

TEST(OptionWriter, WhatIsWrittenReadsBackUnchanged) {
  hglasm::TrackerOptions options;
  options.matcher.genetic.population = 33;
  options.matcher.mbicp.point_to_line = false;
  options.learning.odometry_time_offset.estimate = false;
  options.learning.odometry_time_offset.offset = -0.25;
  options.conversion.max_range = hglasm::kInfinity;
  ParameterTree written;
  hglasm::OptionWriter writer(&written);
  hglasm::visitOptions(writer, &options);

  ParameterValue value;
  ASSERT_TRUE(written.find("genetic/population", &value));
  EXPECT_EQ(value.integer, 33);
  ASSERT_TRUE(written.find("odometry/time_offset", &value));
  EXPECT_EQ(value.number, -0.25);
  hglasm::TrackerOptions read;
  OptionReader reader(written, "~");
  hglasm::visitOptions(reader, &read);
  EXPECT_FALSE(reader.failed()) << reader.error();
  EXPECT_TRUE(reader.unknownPaths().empty());
  ParameterTree again;
  hglasm::OptionWriter rewriter(&again);
  hglasm::visitOptions(rewriter, &read);
  ASSERT_EQ(again.leafPaths(), written.leafPaths());
  for (const std::string& path : written.leafPaths()) {
    ParameterValue a, b;
    written.find(path, &a);
    again.find(path, &b);
    EXPECT_TRUE(a.type == b.type && a.boolean == b.boolean && a.integer == b.integer &&
                a.number == b.number && a.text == b.text)
        << path << ": " << a.describe() << " then " << b.describe();
  }
}

TEST(Inconsistency, NamesBothParametersAndTheirValuesOnceEveryLayerIsApplied) {
  hglasm::TrackerOptions options;
  EXPECT_EQ(hglasm::inconsistency(options, "~"), "");
  options.matcher.genetic.elite_count = options.matcher.genetic.population;
  EXPECT_EQ(hglasm::inconsistency(options, "~"),
            "parameter ~genetic/elite_count must be less than ~genetic/population (100), got 100");
  options = hglasm::TrackerOptions();
  options.conversion.min_range = 5.0;
  options.conversion.max_range = 2.5;
  EXPECT_EQ(hglasm::inconsistency(options, "~"),
            "parameter ~scan/max_range must be greater than ~scan/min_range (5), got 2.5");
}

}  // namespace
