#pragma once

#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace raycarve {

// A small streaming JSON writer for reports: objects, arrays, strings, numbers and booleans,
// with two-space indentation. Non-finite numbers are written as null (JSON has no NaN).
// Misuse (a value without a key inside an object, unbalanced Begin/End) is a programming error
// and CHECK-fails.
class JsonWriter {
 public:
  JsonWriter& BeginObject();
  JsonWriter& EndObject();
  JsonWriter& BeginArray();
  JsonWriter& EndArray();
  JsonWriter& Key(const std::string& key);
  JsonWriter& Value(const std::string& value);
  JsonWriter& Value(const char* value);
  JsonWriter& Value(double value);
  JsonWriter& Value(int64_t value);
  JsonWriter& Value(uint64_t value);
  JsonWriter& Value(int value);
  JsonWriter& Value(bool value);
  JsonWriter& Value(const std::vector<double>& values);  // as a one-line array

  // The document; CHECKs that every object and array was closed.
  std::string str() const;

  static std::string Escape(const std::string& text);

 private:
  void BeforeValue();
  void Newline();

  std::ostringstream out_;
  std::vector<char> stack_;      // '{' or '['
  std::vector<bool> has_items_;  // per open container
  bool after_key_ = false;
};

// A 3-vector as the std::vector that JsonWriter::Value writes as a one-line array.
std::vector<double> JsonArray(const Eigen::Vector3d& v);

}  // namespace raycarve
