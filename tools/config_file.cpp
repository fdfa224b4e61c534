#include "config_file.hpp"

#include <yaml-cpp/yaml.h>

#include <vector>

#include "core/yaml_fields.hpp"
#include "omnivert/core/error.hpp"

namespace omnivert::cli {

namespace {

// The values of one key as CLI11 results: a scalar, or each item of a sequence of scalars.
std::vector<std::string> values_of(const YAML::Node& v,
                                   const std::string& key,
                                   const std::string& file) {
  std::vector<std::string> out;
  if (v.IsScalar()) {
    out.push_back(v.Scalar());
  } else if (v.IsSequence()) {
    for (const YAML::Node& item : v) {
      if (!item.IsScalar())
        throw InputError(file, yaml::line_of(item), "'" + key + "': expected a list of values");
      out.push_back(item.Scalar());
    }
  }
  if (out.empty())
    throw InputError(file, yaml::line_of(v), "'" + key + "': expected a value or a list of values");
  return out;
}

}  // namespace

void add_config_option(CLI::App* cmd, std::string& file) {
  cmd->add_option("--config",
                  file,
                  "YAML file of options: keys are the long options without dashes (image-topic: "
                  "/camera/image_raw, refine: true); the command line wins (docs/import.md)")
      ->check(CLI::ExistingFile);
}

void apply_config(CLI::App* cmd, const std::string& file) {
  if (file.empty()) return;
  const YAML::Node root = yaml::load_file(file);
  for (const auto& kv : root) {
    const std::string key = kv.first.Scalar();
    const int line = yaml::line_of(kv.first);
    CLI::Option* op = key.empty() || key.front() == '-' || key == "config" || key == "help"
                          ? nullptr
                          : cmd->get_option_no_throw("--" + key);
    if (!op) {
      throw InputError(file,
                       line,
                       "unknown key '" + key + "': not an option of `omnivert " + cmd->get_name() +
                           "` (the keys are its long options without the dashes; see --help)");
    }
    if (op->count() > 0) continue;  // given on the command line
    std::vector<std::string> values = values_of(kv.second, key, file);
    if (op->get_items_expected_max() == 1 && values.size() > 1) {  // [a, b] for "a,b"
      std::string joined;
      for (const std::string& v : values) joined += (joined.empty() ? "" : ",") + v;
      values = {joined};
    }
    try {
      for (const std::string& v : values) {
        // A flag: true or false (a negated flag, !--no-x, turns its setting off).
        if (op->get_items_expected_max() == 0) {
          const YAML::Node b = YAML::Load(v);
          bool on = false;
          if (!YAML::convert<bool>::decode(b, on))
            throw InputError(file, line, "'" + key + "': expected true or false, got " + v);
          op->add_result(op->get_flag_value(key, on ? "true" : "false"));
        } else {
          op->add_result(v);
        }
      }
      op->run_callback();
    } catch (const CLI::Error& e) {
      throw InputError(file, line, "'" + key + "': " + e.what());
    }
  }
}

}  // namespace omnivert::cli
