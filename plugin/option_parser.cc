#include "plugin/option_parser.h"

#include <algorithm>
#include <charconv>
#include <iostream>
#include <sstream>

#include "calib/input_error.h"

namespace raycarve {
namespace {

template <typename T>
T ParseNumber(const std::string& name, const std::string& text) {
  T value{};
  const char* end = text.data() + text.size();
  const auto result = std::from_chars(text.data(), end, value);
  if (text.empty() || result.ec != std::errc() || result.ptr != end) {
    throw InputError("--" + name + ": '" + text + "' is not a valid number for this option");
  }
  return value;
}

template <typename T>
std::string ToText(T value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

}  // namespace

OptionParser::OptionParser(std::string command, std::string description)
    : command_(std::move(command)), description_(std::move(description)) {}

OptionParser::Option& OptionParser::Add(const std::string& name,
                                        const std::string& help,
                                        std::string default_text) {
  Option option;
  option.name = name;
  option.help = help;
  option.default_text = std::move(default_text);
  options_.push_back(std::move(option));
  return options_.back();
}

void OptionParser::AddRequired(const std::string& name, std::string* value, const std::string& help) {
  Option& option = Add(name, help, "");
  option.required = true;
  option.assign = [value](const std::string& text) { *value = text; };
}

void OptionParser::AddDefault(const std::string& name,
                              std::string* value,
                              const std::string& help,
                              std::vector<std::string> allowed_values) {
  Option& option = Add(name, help, *value);
  option.allowed_values = std::move(allowed_values);
  option.assign = [value](const std::string& text) { *value = text; };
}

void OptionParser::AddDefault(const std::string& name, int* value, const std::string& help) {
  Add(name, help, ToText(*value)).assign = [value, name](const std::string& text) {
    *value = ParseNumber<int>(name, text);
  };
}

void OptionParser::AddDefault(const std::string& name, uint64_t* value, const std::string& help) {
  Add(name, help, ToText(*value)).assign = [value, name](const std::string& text) {
    *value = ParseNumber<uint64_t>(name, text);
  };
}

void OptionParser::AddDefault(const std::string& name, double* value, const std::string& help) {
  Add(name, help, ToText(*value)).assign = [value, name](const std::string& text) {
    *value = ParseNumber<double>(name, text);
  };
}

void OptionParser::AddDefault(const std::string& name, bool* value, const std::string& help) {
  Option& option = Add(name, help, *value ? "1" : "0");
  option.is_flag = true;
  option.allowed_values = {"0", "1", "true", "false"};
  option.assign = [value](const std::string& text) { *value = text == "1" || text == "true"; };
}

bool OptionParser::Parse(int argc, char** argv, int first) {
  for (int i = first; i < argc; ++i) {
    std::string argument = argv[i];
    if (argument == "--help" || argument == "-h") {
      std::cout << Help();
      return false;
    }
    if (argument.rfind("--", 0) != 0) {
      throw InputError("raycarve " + command_ + ": unexpected argument '" + argument +
                       "' (options are --name value; see --help)");
    }
    std::string name = argument.substr(2);
    std::string value;
    bool has_value = false;
    const size_t equals = name.find('=');
    if (equals != std::string::npos) {
      value = name.substr(equals + 1);
      name = name.substr(0, equals);
      has_value = true;
    }
    auto option = std::find_if(
        options_.begin(), options_.end(), [&](const Option& o) { return o.name == name; });
    if (option == options_.end()) {
      throw InputError("raycarve " + command_ + ": unknown option --" + name + " (see --help)");
    }
    if (!has_value) {
      const bool next_is_value = i + 1 < argc && std::string(argv[i + 1]).rfind("--", 0) != 0;
      if (next_is_value) {
        value = argv[++i];
      } else if (option->is_flag) {
        value = "1";
      } else {
        throw InputError("raycarve " + command_ + ": option --" + name + " needs a value");
      }
    }
    if (!option->allowed_values.empty() &&
        std::find(option->allowed_values.begin(), option->allowed_values.end(), value) ==
            option->allowed_values.end()) {
      std::string allowed;
      for (const std::string& v : option->allowed_values) allowed += (allowed.empty() ? "" : ", ") + v;
      throw InputError("raycarve " + command_ + ": --" + name + " '" + value +
                       "' is not one of: " + allowed);
    }
    option->assign(value);
    option->set = true;
  }
  for (const Option& option : options_) {
    if (option.required && !option.set) {
      throw InputError("raycarve " + command_ + ": option --" + option.name +
                       " is required (see --help)");
    }
  }
  return true;
}

bool OptionParser::IsSet(const std::string& name) const {
  for (const Option& option : options_) {
    if (option.name == name) return option.set;
  }
  return false;
}

std::string OptionParser::Help() const {
  std::ostringstream text;
  text << "Usage: raycarve " << command_ << " [options]\n\n" << description_ << "\n\nOptions:\n";
  for (const Option& option : options_) {
    text << "  --" << option.name << "\n      " << option.help;
    if (!option.allowed_values.empty() && !option.is_flag) {
      text << "\n      allowed: ";
      for (size_t k = 0; k < option.allowed_values.size(); ++k) {
        text << (k ? ", " : "") << option.allowed_values[k];
      }
    }
    text << (option.required ? "\n      (required)" : "\n      default: " + option.default_text)
         << "\n";
  }
  return text.str();
}

}  // namespace raycarve
