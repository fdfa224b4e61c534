// libFuzzer harness of the checked YAML reading every sensor.yaml and config file goes through
// (core/yaml_fields): the calls of `omnivert calibrate --prior` (tools/cmd_calibrate.cpp,
// read_prior_file) and of the sensor files, on one fuzzed file.

#include <cmath>
#include <cstdint>
#include <cstdlib>

#include <yaml-cpp/yaml.h>

#include "core/yaml_fields.hpp"
#include "fuzz_support.hpp"

namespace {

void check(const std::optional<double>& v) {
  if (v && !std::isfinite(*v)) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = (omnivert::fuzz::scratch() / "prior.yaml").string();
  omnivert::fuzz::write_file(path, omnivert::fuzz::as_text(data, size));
  namespace y = omnivert::yaml;
  omnivert::fuzz::expect_input_error_or_success([&] {
    const YAML::Node root = y::load_file(path);
    check(y::optional_number(root, "phi", path));
    check(y::optional_number(root, "rho", path, true));
    check(y::optional_number(root, "sigma_phi", path, true));
    check(y::optional_number(root, "odometry_inflation", path, true));
    (void)y::optional_string(root, "unit", path);
    if (const auto v = y::optional_numbers(root, "resolution", 2, path)) {
      if (v->size() != 2) std::abort();
    }
    (void)y::line_of(root["psi"]);
    const double w = y::required_number(root, "wheel_base", path, true);
    if (!std::isfinite(w) || w < 0) std::abort();
  });
  return 0;
}
