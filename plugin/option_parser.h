#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace raycarve {

// Command-line options in COLMAP's style: `--name value` or `--name=value`, every option with a
// default or marked required, and a help text listing defaults and allowed values.
//
// `--project_path FILE.ini` reads options from COLMAP's INI format first (key=value lines;
// keys outside a section or under [raycarve] or [<command>] that the command takes are set, the
// rest, such as COLMAP's own sections, left alone); the command line overrides it.
//
// Parse throws InputError on an unknown option, a missing value, a value that does not parse as
// the option's type or is not among its allowed values, or a missing required option. `--help`
// makes Parse return false after printing the help to stdout: the options a user changes first
// when the command names them (SetBasicOptions), every option by group with `--help all`, and the
// examples. `--help_markdown` prints every option as Markdown (docs/cli.md is made from it).
// An option file read is protected as an input: no output may replace it (ProtectInputFile).

class OptionParser {
 public:
  OptionParser(std::string command, std::string description);

  void AddRequired(const std::string& name, std::string* value, const std::string& help);
  void AddDefault(const std::string& name,
                  std::string* value,
                  const std::string& help,
                  std::vector<std::string> allowed_values = {});
  void AddDefault(const std::string& name, int* value, const std::string& help);
  void AddDefault(const std::string& name, uint64_t* value, const std::string& help);
  void AddDefault(const std::string& name, double* value, const std::string& help);
  void AddDefault(const std::string& name, bool* value, const std::string& help);

  // An old name of an option: still accepted, with a warning that it is deprecated.
  void AddDeprecatedName(const std::string& old_name, const std::string& name);

  // Options added from now on belong to the group `title` ("Carve", "Mesh", ...), which the help
  // lists under that title; options added before any group are listed first, untitled.
  void BeginGroup(const std::string& title);
  // The options `--help` shows (the rest with `--help all`); none given: `--help` shows all.
  void SetBasicOptions(std::vector<std::string> names);
  // An example command line for the end of the help, with what it does.
  void AddExample(const std::string& command_line, const std::string& what);

  // Parses argv[first..argc); returns false when --help was asked for.
  bool Parse(int argc, char** argv, int first = 2);

  // True when the option was given on the command line (not left at its default).
  bool IsSet(const std::string& name) const;

  // The help text: the basic options only, or every option by group (`all`).
  std::string Help(bool all = true) const;
  // Every option as a Markdown section: a table per group, then the examples.
  std::string Markdown() const;

 private:
  struct Option {
    std::string name;
    std::string help;
    std::string default_text;
    std::vector<std::string> allowed_values;
    bool required = false;
    bool is_flag = false;  // bool: "--name" alone means true
    bool set = false;
    std::function<void(const std::string&)> assign;
    std::string group;  // BeginGroup's title when it was added
  };
  // One option's lines in the help text.
  static std::string OptionHelp(const Option& option);
  // The groups' titles in the order they were first added, the untitled group first.
  std::vector<std::string> Groups() const;
  Option& Add(const std::string& name, const std::string& help, std::string default_text);
  // Checks `value` against the option's allowed values and assigns it.
  void Assign(Option* option, const std::string& value);
  // --project_path: COLMAP's INI format; known keys (top level, [raycarve], [<command>]) set.
  void ReadProjectFile(const std::string& path);

  std::string command_;
  std::string description_;
  std::vector<Option> options_;
  std::vector<std::pair<std::string, std::string>> deprecated_;  // old name, current name
  std::string group_;                                             // the group being added
  std::vector<std::string> basic_;                                // --help's options
  std::vector<std::pair<std::string, std::string>> examples_;     // command line, what it does
};

}  // namespace raycarve
