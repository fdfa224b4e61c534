// Uses the estimator alone (omnivert::calib): a straight run's verdict, without OpenCV.
#include <cstdio>

#include <omnivert/calib/calibrate.hpp>

int main() {
  omnivert::calib::CalibrationRun run;
  for (int i = 0; i < 10; ++i) run.frames.push_back({});
  const auto options = omnivert::calib::recommended_options();
  std::string why;
  return options.IsValid(&why) && run.frames.size() == 10 ? 0 : 1;
}
