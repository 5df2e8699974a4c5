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

  static inline std::string* root_ = nullptr;
};

}  // namespace testing
}  // namespace raycarve
