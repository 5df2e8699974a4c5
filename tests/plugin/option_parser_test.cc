#include "plugin/option_parser.h"

#include <gtest/gtest.h>

#include "calib/input_error.h"

namespace raycarve {
namespace {

struct Argv {
  explicit Argv(std::vector<std::string> args) : strings(std::move(args)) {
    for (std::string& s : strings) pointers.push_back(s.data());
  }
  int argc() const { return static_cast<int>(pointers.size()); }
  char** argv() { return pointers.data(); }
  std::vector<std::string> strings;
  std::vector<char*> pointers;
};

TEST(OptionParser, ParsesColmapStyleOptionsOfEveryType) {
  std::string path, format = "text";
  int views = 8;
  double margin = 0.1;
  bool skip = false;
  uint64_t seed = 1;
  OptionParser parser("cmd", "description");
  parser.AddRequired("input_path", &path, "model");
  parser.AddDefault("format", &format, "format", {"text", "json"});
  parser.AddDefault("views", &views, "views");
  parser.AddDefault("margin", &margin, "margin");
  parser.AddDefault("skip", &skip, "skip");
  parser.AddDefault("seed", &seed, "seed");
  Argv args({"raycarve", "cmd", "--input_path", "a b", "--format=json", "--views", "12",
             "--margin", "0.25", "--skip", "--seed", "18446744073709551615"});
  ASSERT_TRUE(parser.Parse(args.argc(), args.argv()));
  EXPECT_EQ(path, "a b");
  EXPECT_EQ(format, "json");
  EXPECT_EQ(views, 12);
  EXPECT_EQ(margin, 0.25);
  EXPECT_TRUE(skip);
  EXPECT_EQ(seed, 18446744073709551615ull);
  EXPECT_TRUE(parser.IsSet("views"));
  const std::string help = parser.Help();
  EXPECT_NE(help.find("--format"), std::string::npos);
  EXPECT_NE(help.find("allowed: text, json"), std::string::npos) << help;
  EXPECT_NE(help.find("default: text"), std::string::npos) << help;
  EXPECT_NE(help.find("(required)"), std::string::npos) << help;
}

TEST(OptionParser, RefusesUnknownMissingAndMalformedOptionsByName) {
  auto expect_error = [](std::vector<std::string> args, const std::string& part) {
    std::string path;
    int views = 8;
    std::string format = "text";
    OptionParser parser("cmd", "d");
    parser.AddRequired("input_path", &path, "model");
    parser.AddDefault("views", &views, "views");
    parser.AddDefault("format", &format, "format", {"text", "json"});
    args.insert(args.begin(), {"raycarve", "cmd"});
    Argv argv(args);
    try {
      parser.Parse(argv.argc(), argv.argv());
      ADD_FAILURE() << "accepted";
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find(part), std::string::npos) << error.what();
    }
  };
  expect_error({"--input_path", "x", "--colour", "1"}, "unknown option --colour");
  expect_error({"--views", "3"}, "--input_path is required");
  expect_error({"--input_path", "x", "--views", "3x"}, "--views: '3x'");
  expect_error({"--input_path", "x", "--views"}, "--views needs a value");
  expect_error({"--input_path", "x", "--format", "xml"}, "not one of: text, json");
  expect_error({"--input_path", "x", "stray"}, "unexpected argument 'stray'");
}

}  // namespace
}  // namespace raycarve
