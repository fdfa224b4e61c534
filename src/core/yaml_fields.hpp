#pragma once
// Checked reading of YAML fields with messages that name the file, the line and the field.
// Used by every reader of sensor.yaml and config files.

#include <optional>
#include <string>
#include <vector>

namespace YAML {
class Node;
}

namespace omnivert::yaml {

// Loads a YAML file; throws InputError if it is missing, unreadable or not valid YAML, or if
// its top level is not a mapping.
YAML::Node load_file(const std::string& path);

// A number under key; nullopt if the key is absent. Throws InputError (file:line, key) for a
// value that is not a finite number, or a negative one when non_negative is set.
std::optional<double> optional_number(const YAML::Node& map,
                                      const std::string& key,
                                      const std::string& file,
                                      bool non_negative = false);
double required_number(const YAML::Node& map,
                       const std::string& key,
                       const std::string& file,
                       bool non_negative = false);
// A sequence of exactly n numbers under key; nullopt if absent.
std::optional<std::vector<double>> optional_numbers(const YAML::Node& map,
                                                    const std::string& key,
                                                    std::size_t n,
                                                    const std::string& file);
std::optional<std::string> optional_string(const YAML::Node& map,
                                           const std::string& key,
                                           const std::string& file);
// 1-based line of a node, for messages; 0 for an absent key.
int line_of(const YAML::Node& node);

}  // namespace omnivert::yaml
