#pragma once
// --config FILE.yaml: a subcommand's options from a file (docs/import.md#config-file). The keys
// are the long options without their dashes (`image-topic: /camera/image_raw`, `refine: true`,
// `wheel-joints: [left, right]` or `left,right`); an option given on the command line wins over
// the file. A key that is not an option of the subcommand is refused with the file, its line
// and the key.
//
// Read with yaml-cpp rather than CLI11's own config support: CLI11 2.1 (Debian 12) reads only
// TOML and INI, and a config set on a subcommand takes its keys under the subcommand's section
// and passes unknown keys on to the parent app, where they are not refused with their line.

#include <string>

#include <CLI/CLI.hpp>

namespace omnivert::cli {

// Adds --config FILE to `cmd`.
void add_config_option(CLI::App* cmd, std::string& file);

// Applies the file's values to the options of `cmd` that the command line did not give (at the
// start of the subcommand's callback). Nothing when `file` is empty. Throws InputError naming
// the file and line for an unknown key or a value the option refuses.
void apply_config(CLI::App* cmd, const std::string& file);

}  // namespace omnivert::cli
