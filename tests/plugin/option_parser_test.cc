#include "plugin/option_parser.h"

#include <gtest/gtest.h>

#include "calib/input_error.h"
#include "tests/test_support.h"

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

TEST(OptionParser, ReadsIniFilesWithAByteOrderMarkAndCrlfAsColmapDoes) {
  const std::string folder = testing::MakeTemporaryDirectory("option_parser_ini");
  const std::string ini = folder + "/options.ini";
  testing::WriteFile(ini, "\xEF\xBB\xBFviews=12\r\n[cmd]\r\nmargin = 0.5\r\n");
  int views = 8;
  double margin = 0.1;
  OptionParser parser("cmd", "description");
  parser.AddDefault("views", &views, "views");
  parser.AddDefault("margin", &margin, "margin");
  Argv args({"raycarve", "cmd", "--project_path", ini});
  ASSERT_TRUE(parser.Parse(args.argc(), args.argv()));
  EXPECT_EQ(views, 12);
  EXPECT_EQ(margin, 0.5);
}

TEST(OptionParser, AProjectPathWithoutItsValueIsAnErrorWhereverItStands) {
  for (const std::vector<std::string>& arguments :
       {std::vector<std::string>{"raycarve", "cmd", "--project_path"},
        std::vector<std::string>{"raycarve", "cmd", "--views", "3", "--project_path"}}) {
    int views = 8;
    OptionParser parser("cmd", "description");
    parser.AddDefault("views", &views, "views");
    Argv args(arguments);
    try {
      parser.Parse(args.argc(), args.argv());
      ADD_FAILURE() << "accepted --project_path without a value";
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find("--project_path needs a value"), std::string::npos)
          << error.what();
    }
  }
}

TEST(OptionParser, GroupsTheHelpAndShowsTheBasicOptionsFirst) {
  int views = 8, level = 1;
  std::string mesh = "smooth";
  OptionParser parser("cmd", "description");
  parser.BeginGroup("Carve");
  parser.AddDefault("views", &views, "views");
  parser.AddDefault("level", &level, "level");
  parser.BeginGroup("Mesh");
  parser.AddDefault("mesh", &mesh, "the mesh", {"smooth", "voxels"});
  parser.SetBasicOptions({"mesh"});
  parser.AddExample("raycarve cmd --mesh voxels", "voxel faces");
  const std::string basic = parser.Help(false);
  EXPECT_NE(basic.find("--mesh"), std::string::npos) << basic;
  EXPECT_EQ(basic.find("--level"), std::string::npos) << basic;
  EXPECT_NE(basic.find("--help all"), std::string::npos) << basic;
  EXPECT_NE(basic.find("raycarve cmd --mesh voxels"), std::string::npos) << basic;
  const std::string all = parser.Help(true);
  EXPECT_LT(all.find("Carve options:"), all.find("--level")) << all;
  EXPECT_LT(all.find("--level"), all.find("Mesh options:")) << all;
  const std::string markdown = parser.Markdown();
  EXPECT_NE(markdown.find("| `--mesh` * | `smooth` | the mesh (allowed: smooth, voxels) |"),
            std::string::npos)
      << markdown;
}

}  // namespace
}  // namespace raycarve
