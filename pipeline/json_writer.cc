#include "pipeline/json_writer.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <locale>

#include <glog/logging.h>
#include <opencv2/imgcodecs.hpp>

#include "calib/atomic_file.h"
#include "calib/input_error.h"

namespace raycarve {

std::string JsonWriter::Escape(const std::string& text) {
  std::string escaped = "\"";
  for (const char c : text) {
    switch (c) {
      case '"': escaped += "\\\""; break;
      case '\\': escaped += "\\\\"; break;
      case '\n': escaped += "\\n"; break;
      case '\r': escaped += "\\r"; break;
      case '\t': escaped += "\\t"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buffer[8];
          std::snprintf(buffer, sizeof(buffer), "\\u%04x", c);
          escaped += buffer;
        } else {
          escaped += c;
        }
    }
  }
  return escaped + "\"";
}

void JsonWriter::Newline() {
  out_ << "\n" << std::string(2 * stack_.size(), ' ');
}

void JsonWriter::BeforeValue() {
  if (stack_.empty()) {
    CHECK(out_.tellp() == 0) << "a JSON document holds one top-level value";
    return;
  }
  if (stack_.back() == '{') {
    CHECK(after_key_) << "a value inside a JSON object needs a key";
    after_key_ = false;
    return;
  }
  if (has_items_.back()) out_ << ",";
  has_items_.back() = true;
  Newline();
}

JsonWriter& JsonWriter::BeginObject() {
  BeforeValue();
  out_ << "{";
  stack_.push_back('{');
  has_items_.push_back(false);
  return *this;
}

JsonWriter& JsonWriter::EndObject() {
  CHECK(!stack_.empty() && stack_.back() == '{' && !after_key_);
  const bool had_items = has_items_.back();
  stack_.pop_back();
  has_items_.pop_back();
  if (had_items) Newline();
  out_ << "}";
  return *this;
}

JsonWriter& JsonWriter::BeginArray() {
  BeforeValue();
  out_ << "[";
  stack_.push_back('[');
  has_items_.push_back(false);
  return *this;
}

JsonWriter& JsonWriter::EndArray() {
  CHECK(!stack_.empty() && stack_.back() == '[');
  const bool had_items = has_items_.back();
  stack_.pop_back();
  has_items_.pop_back();
  if (had_items) Newline();
  out_ << "]";
  return *this;
}

JsonWriter& JsonWriter::Key(const std::string& key) {
  CHECK(!stack_.empty() && stack_.back() == '{' && !after_key_);
  if (has_items_.back()) out_ << ",";
  has_items_.back() = true;
  Newline();
  out_ << Escape(key) << ": ";
  after_key_ = true;
  return *this;
}

JsonWriter& JsonWriter::Value(const std::string& value) {
  BeforeValue();
  out_ << Escape(value);
  return *this;
}

JsonWriter& JsonWriter::Value(const char* value) { return Value(std::string(value)); }

JsonWriter& JsonWriter::Value(double value) {
  BeforeValue();
  if (std::isfinite(value)) {
    char buffer[32];
    std::snprintf(buffer, sizeof(buffer), "%.12g", value);
    out_ << buffer;
  } else {
    out_ << "null";
  }
  return *this;
}

JsonWriter& JsonWriter::Value(int64_t value) {
  BeforeValue();
  out_ << value;
  return *this;
}

JsonWriter& JsonWriter::Value(uint64_t value) {
  BeforeValue();
  out_ << value;
  return *this;
}

JsonWriter& JsonWriter::Value(int value) { return Value(static_cast<int64_t>(value)); }

JsonWriter& JsonWriter::Value(bool value) {
  BeforeValue();
  out_ << (value ? "true" : "false");
  return *this;
}

JsonWriter& JsonWriter::Value(const std::vector<double>& values) {
  BeforeValue();
  out_ << "[";
  for (size_t i = 0; i < values.size(); ++i) {
    char buffer[32];
    if (std::isfinite(values[i])) {
      std::snprintf(buffer, sizeof(buffer), "%.12g", values[i]);
    } else {
      std::snprintf(buffer, sizeof(buffer), "null");
    }
    out_ << (i ? ", " : "") << buffer;
  }
  out_ << "]";
  return *this;
}

std::string JsonWriter::str() const {
  CHECK(stack_.empty()) << "unclosed JSON object or array";
  return out_.str() + "\n";
}

std::vector<double> JsonArray(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace raycarve
