#include "plugin/option_parser.h"

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include <glog/logging.h>

#include "calib/input_error.h"
#include "pipeline/output_files.h"

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
  option.group = group_;
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

void OptionParser::Assign(Option* option, const std::string& value) {
  if (!option->allowed_values.empty() &&
      std::find(option->allowed_values.begin(), option->allowed_values.end(), value) ==
          option->allowed_values.end()) {
    std::string allowed;
    for (const std::string& v : option->allowed_values) allowed += (allowed.empty() ? "" : ", ") + v;
    throw InputError("--" + option->name + " '" + value + "' is not one of: " + allowed);
  }
  option->assign(value);
  option->set = true;
}

void OptionParser::ReadProjectFile(const std::string& path) {
  ProtectInputFile(path, "option file (--project_path " + path + ")");
  std::error_code error;
  const uintmax_t size = std::filesystem::file_size(path, error);
  if (error || !std::filesystem::is_regular_file(path)) {
    throw InputError(path + ": --project_path: not a readable file");
  }
  if (size > (1u << 20)) {
    throw InputError(path + ": --project_path: " + std::to_string(size) +
                     " bytes; an option file holds at most 1 MiB");
  }
  std::ifstream file(path);
  std::string line, section;
  std::vector<std::string> ignored;
  for (int number = 1; std::getline(file, line); ++number) {
    // A UTF-8 byte-order mark (editors on Windows write one) is not part of the first key.
    if (number == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);
    const auto trim = [](std::string text) {
      const size_t begin = text.find_first_not_of(" \t\r");
      const size_t end = text.find_last_not_of(" \t\r");
      return begin == std::string::npos ? std::string() : text.substr(begin, end - begin + 1);
    };
    line = trim(line);
    if (line.empty() || line[0] == '#' || line[0] == ';') continue;
    if (line.front() == '[' && line.back() == ']') {
      section = trim(line.substr(1, line.size() - 2));
      continue;
    }
    const size_t equals = line.find('=');
    if (equals == std::string::npos) {
      throw InputError(path + ":" + std::to_string(number) + ": expected key=value or [section], got '" +
                       line + "'");
    }
    const std::string key = trim(line.substr(0, equals));
    const std::string value = trim(line.substr(equals + 1));
    // Top-level keys and those under [raycarve] or [<command>] are this command's; COLMAP's own
    // sections ([SiftExtraction], ...) and keys this command does not take are left to COLMAP.
    const bool ours = section.empty() || section == "raycarve" || section == command_;
    auto option = std::find_if(options_.begin(), options_.end(),
                               [&](const Option& o) { return o.name == key; });
    if (!ours || option == options_.end()) {
      ignored.push_back(section.empty() ? key : section + "." + key);
      continue;
    }
    try {
      Assign(&*option, value);
    } catch (const InputError& bad) {
      throw InputError(path + ":" + std::to_string(number) + ": " + bad.what());
    }
  }
  if (!ignored.empty()) {
    std::string names;
    for (size_t k = 0; k < ignored.size() && k < 8; ++k) names += (k ? ", " : "") + ignored[k];
    if (ignored.size() > 8) names += ", ...";
    LOG(INFO) << path << ": " << ignored.size() << " keys that raycarve " << command_
              << " does not take were left alone (" << names << ")";
  }
}

void OptionParser::AddDeprecatedName(const std::string& old_name, const std::string& name) {
  deprecated_.emplace_back(old_name, name);
}

bool OptionParser::Parse(int argc, char** argv, int first) {
  // An option file first, so that the command line overrides it.
  for (int i = first; i < argc; ++i) {
    const std::string argument = argv[i];
    if (argument == "--project_path" && i + 1 < argc) {
      ReadProjectFile(argv[i + 1]);
    } else if (argument.rfind("--project_path=", 0) == 0) {
      ReadProjectFile(argument.substr(std::string("--project_path=").size()));
    }
  }
  for (int i = first; i < argc; ++i) {
    std::string argument = argv[i];
    if (argument == "--help" || argument == "-h") {
      std::cout << Help(basic_.empty() || (i + 1 < argc && std::string(argv[i + 1]) == "all"));
      return false;
    }
    if (argument == "--help_markdown") {
      std::cout << Markdown();
      return false;
    }
    if (argument.rfind("--", 0) != 0) {
      throw InputError("unexpected argument '" + argument +
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
    if (name == "project_path") {
      if (!has_value && (i + 1 >= argc || std::string(argv[i + 1]).rfind("--", 0) == 0)) {
        throw InputError("option --project_path needs a value (an INI file)");
      }
      if (!has_value) ++i;  // read above
      continue;
    }
    for (const auto& [old_name, current] : deprecated_) {
      if (name == old_name) {
        LOG(WARNING) << "raycarve " << command_ << ": --" << old_name << " is deprecated; use --"
                     << current;
        name = current;
        break;
      }
    }
    auto option = std::find_if(
        options_.begin(), options_.end(), [&](const Option& o) { return o.name == name; });
    if (option == options_.end()) {
      throw InputError("unknown option --" + name + " (see --help)");
    }
    if (!has_value) {
      const bool next_is_value = i + 1 < argc && std::string(argv[i + 1]).rfind("--", 0) != 0;
      if (next_is_value) {
        value = argv[++i];
      } else if (option->is_flag) {
        value = "1";
      } else {
        throw InputError("option --" + name + " needs a value");
      }
    }
    Assign(&*option, value);
  }
  for (const Option& option : options_) {
    if (option.required && !option.set) {
      throw InputError("option --" + option.name + " is required (see --help)");
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

void OptionParser::BeginGroup(const std::string& title) { group_ = title; }

void OptionParser::SetBasicOptions(std::vector<std::string> names) {
  for (const std::string& name : names) {
    CHECK(std::any_of(options_.begin(), options_.end(),
                      [&](const Option& o) { return o.name == name; }))
        << "basic option --" << name << " was never added";
  }
  basic_ = std::move(names);
}

void OptionParser::AddExample(const std::string& command_line, const std::string& what) {
  examples_.emplace_back(command_line, what);
}

std::vector<std::string> OptionParser::Groups() const {
  // In the order the groups were first added; the untitled group first.
  std::vector<std::string> groups;
  for (const Option& option : options_) {
    if (std::find(groups.begin(), groups.end(), option.group) == groups.end()) {
      groups.push_back(option.group);
    }
  }
  std::stable_partition(groups.begin(), groups.end(), [](const std::string& g) { return g.empty(); });
  return groups;
}

std::string OptionParser::OptionHelp(const Option& option) {
  std::string text = "  --" + option.name + "\n      " + option.help;
  if (!option.allowed_values.empty() && !option.is_flag) {
    text += "\n      allowed: ";
    for (size_t k = 0; k < option.allowed_values.size(); ++k) {
      text += (k ? ", " : "") + option.allowed_values[k];
    }
  }
  return text + (option.required ? "\n      (required)" : "\n      default: " + option.default_text) +
         "\n";
}

std::string OptionParser::Help(bool all) const {
  std::ostringstream text;
  text << "Usage: raycarve " << command_ << " [options]\n\n" << description_ << "\n";
  if (!all) {
    text << "\nThe options changed most often (every option, by stage: --help all):\n";
    for (const std::string& name : basic_) {
      for (const Option& option : options_) {
        if (option.name == name) text << OptionHelp(option);
      }
    }
  } else {
    for (const std::string& group : Groups()) {
      text << "\n" << (group.empty() ? std::string("Options") : group + " options") << ":\n";
      for (const Option& option : options_) {
        if (option.group == group) text << OptionHelp(option);
      }
    }
    for (const auto& [old_name, current] : deprecated_) {
      text << "  --" << old_name << "\n      deprecated name of --" << current << "\n";
    }
  }
  if (!examples_.empty()) {
    text << "\nExamples:\n";
    for (const auto& [line, what] : examples_) text << "  " << line << "\n      " << what << "\n";
  }
  text << "\nEvery command also takes --project_path FILE.ini (COLMAP's option files: key=value\n"
          "lines, [sections]; the command line overrides it) and glog's --log_to_stderr,\n"
          "--log_level and --v as COLMAP does.\n";
  return text.str();
}

std::string OptionParser::Markdown() const {
  // Table cells: pipes escaped, so that a value list stays in its cell.
  const auto cell = [](const std::string& text) {
    std::string escaped;
    for (char c : text) {
      escaped += c == '|' ? std::string("\\|")
                 : c == '<' ? std::string("&lt;")
                 : c == '>' ? std::string("&gt;")
                            : std::string(1, c);
    }
    return escaped;
  };
  std::ostringstream text;
  text << "## raycarve " << command_ << "\n\n" << description_ << "\n";
  for (const std::string& group : Groups()) {
    text << "\n" << (group.empty() ? std::string("**Options**") : "**" + group + "**") << "\n\n"
         << "| option | default | what it does |\n|---|---|---|\n";
    for (const Option& option : options_) {
      if (option.group != group) continue;
      std::string help = option.help;
      if (!option.allowed_values.empty() && !option.is_flag) {
        help += " (allowed: ";
        for (size_t k = 0; k < option.allowed_values.size(); ++k) {
          help += (k ? ", " : "") + option.allowed_values[k];
        }
        help += ")";
      }
      const bool basic = std::find(basic_.begin(), basic_.end(), option.name) != basic_.end();
      text << "| `--" << option.name << "`" << (basic ? " *" : "") << " | "
           << (option.required              ? std::string("required")
               : option.default_text.empty() ? std::string("(none)")
                                             : "`" + cell(option.default_text) + "`")
           << " | " << cell(help) << " |\n";
    }
  }
  if (!examples_.empty()) {
    text << "\nExamples:\n\n";
    for (const auto& [line, what] : examples_) text << "- `" << line << "`: " << what << "\n";
  }
  return text.str();
}

}  // namespace raycarve
