#pragma once

#include <string>
#include <vector>

namespace raycarve {

// The glue that drives the installed `colmap` program (3.8, CPU build).

// The program to run: `colmap_path` itself when it names a file, else the first match on PATH.
// Throws InputError saying how to install it when there is none.
std::string FindColmap(const std::string& colmap_path);

// Runs `colmap <arguments>` (each argument passed as one word, no shell expansion), copies
// every line it prints to stdout prefixed with "  colmap| ", and returns its exit status. The
// last lines it printed are kept in `tail` (for error messages). Throws InputError when the
// program cannot be started.
int RunColmap(const std::string& colmap,
              const std::vector<std::string>& arguments,
              std::vector<std::string>* tail);

// Quotes a word for /bin/sh (single quotes).
std::string ShellQuote(const std::string& word);

}  // namespace raycarve
