#pragma once

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "tests/test_support.h"

namespace raycarve {
namespace testing {

// A test suite's temporary folder holding one project that `raycarve synth` generated for the
// whole suite. A suite derives from it and calls MakeProject in its SetUpTestSuite.
class GeneratedProject : public ::testing::Test {
 protected:
  // Makes the suite's folder (named `name`) and generates <folder>/project with `synth_options`.
  static void MakeProject(const std::string& name, const std::string& synth_options) {
    root_ = new std::string(MakeTemporaryDirectory(name));
    std::string output;
    ASSERT_EQ(RunRaycarve("synth --output_path " + Project() + " " + synth_options, &output), 0)
        << output;
  }
  static void TearDownTestSuite() {
    std::filesystem::remove_all(*root_);
    delete root_;
    root_ = nullptr;
  }

  static std::string Project() { return *root_ + "/project"; }

  static int Run(const std::string& arguments, std::string* output) {
    return RunRaycarve(arguments, output);
  }

  // A copy of the project's model in `format` (BIN as written, or TXT) to corrupt.
  static std::string CopyModel(const std::string& name, const std::string& format = "BIN") {
    const std::string copy = *root_ + "/" + name;
    std::filesystem::remove_all(copy);
    std::string output;
    EXPECT_EQ(Run("model_converter --input_path " + Project() + "/sparse/0 --output_path " + copy +
                      " --output_type " + format,
                  &output),
              0)
        << output;
    return copy;
  }

  static inline std::string* root_ = nullptr;
};

// A project of 4 RADIAL photos of 96 x 72 pixels and 300 sparse points.
class SmallRadialProject : public GeneratedProject {
 protected:
  static void SetUpTestSuite() {
    MakeProject("radial_project", "--views 4 --width 96 --height 72 --points 300 --camera_model RADIAL");
  }
};

}  // namespace testing
}  // namespace raycarve
