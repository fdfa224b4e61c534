#include "core/yaml_fields.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>

#include <yaml-cpp/yaml.h>

#include "omnivert/core/error.hpp"
#include "omnivert/core/file_io.hpp"

namespace omnivert::yaml {

// 0 (no line) for a key that is absent: its node has no mark.
int line_of(const YAML::Node& node) { return node.IsDefined() ? node.Mark().line + 1 : 0; }

YAML::Node load_file(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(path, 0, "file not found");
  if (fs::is_directory(path, ec)) throw InputError(path, 0, "is a directory, expected a YAML file");
  if (const std::string why = unreadable_file_reason(path); !why.empty()) {
    throw InputError(path, 0, why);
  }
  std::ifstream in(path);
  if (!in) throw InputError(path, 0, "cannot be opened for reading");
  YAML::Node root;
  try {
    root = YAML::Load(in);
  } catch (const YAML::ParserException& e) {
    throw InputError(path, e.mark.line + 1, "not valid YAML: " + e.msg);
  }
  if (!root.IsMap()) throw InputError(path, 0, "expected a mapping of fields at the top level");
  return root;
}

namespace {

double parse_number(const YAML::Node& node, const std::string& key, const std::string& file) {
  if (!node.IsScalar()) {
    throw InputError(file, line_of(node), "field '" + key + "' must be a number");
  }
  double v = 0.0;
  try {
    v = node.as<double>();
  } catch (const YAML::Exception&) {
    throw InputError(
        file, line_of(node), "field '" + key + "' must be a number, got '" + node.Scalar() + "'");
  }
  if (!std::isfinite(v)) {
    throw InputError(file, line_of(node), "field '" + key + "' must be finite");
  }
  return v;
}

}  // namespace

std::optional<double> optional_number(const YAML::Node& map,
                                      const std::string& key,
                                      const std::string& file,
                                      bool non_negative) {
  const YAML::Node node = map[key];
  if (!node || node.IsNull()) return std::nullopt;
  const double v = parse_number(node, key, file);
  if (non_negative && v < 0.0) {
    throw InputError(
        file, line_of(node), "field '" + key + "' must not be negative, got " + node.Scalar());
  }
  return v;
}

double required_number(const YAML::Node& map,
                       const std::string& key,
                       const std::string& file,
                       bool non_negative) {
  auto v = optional_number(map, key, file, non_negative);
  if (!v) throw InputError(file, 0, "missing required field '" + key + "'");
  return *v;
}

std::optional<std::vector<double>> optional_numbers(const YAML::Node& map,
                                                    const std::string& key,
                                                    std::size_t n,
                                                    const std::string& file) {
  const YAML::Node node = map[key];
  if (!node || node.IsNull()) return std::nullopt;
  if (!node.IsSequence() || node.size() != n) {
    throw InputError(file,
                     line_of(node),
                     "field '" + key + "' must be a list of " + std::to_string(n) + " numbers");
  }
  std::vector<double> out;
  out.reserve(n);
  for (std::size_t i = 0; i < n; ++i) out.push_back(parse_number(node[i], key, file));
  return out;
}

std::optional<std::string> optional_string(const YAML::Node& map,
                                           const std::string& key,
                                           const std::string& file) {
  const YAML::Node node = map[key];
  if (!node || node.IsNull()) return std::nullopt;
  if (!node.IsScalar()) {
    throw InputError(file, line_of(node), "field '" + key + "' must be a single value");
  }
  return node.Scalar();
}

}  // namespace omnivert::yaml
