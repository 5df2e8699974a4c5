#include "pipeline/json_writer.h"
#include "pipeline/output_files.h"

#include <cmath>

#include <gtest/gtest.h>

namespace raycarve {
namespace {

TEST(JsonWriter, WritesNestedDocumentsWithEscapesAndNullForNonFinite) {
  JsonWriter json;
  json.BeginObject()
      .Key("name").Value("a \"quoted\"\\path\n")
      .Key("count").Value(3)
      .Key("ratio").Value(0.5)
      .Key("bad").Value(std::nan(""))
      .Key("ok").Value(true)
      .Key("list").BeginArray().Value(1).Value("two").BeginObject().EndObject().EndArray()
      .Key("vector").Value(std::vector<double>{1.5, INFINITY})
      .EndObject();
  EXPECT_EQ(json.str(),
            "{\n"
            "  \"name\": \"a \\\"quoted\\\"\\\\path\\n\",\n"
            "  \"count\": 3,\n"
            "  \"ratio\": 0.5,\n"
            "  \"bad\": null,\n"
            "  \"ok\": true,\n"
            "  \"list\": [\n"
            "    1,\n"
            "    \"two\",\n"
            "    {}\n"
            "  ],\n"
            "  \"vector\": [1.5, null]\n"
            "}\n");
}

}  // namespace
}  // namespace raycarve
