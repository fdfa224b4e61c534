#pragma once
// The descriptor's sensitivity study (the paper's Sec. 6, Figs. 13-18) on a study set
// (descriptor_study.hpp), written as CSV and PNG files (docs/study.md):
//  - Fig. 13: % correct nearest neighbour against the clipping threshold;
//  - Fig. 14: against Gaussian image noise (sigma in % of 255);
//  - Fig. 15: against the orientation bins and areas, with the average precision of the
//    ratio test;
//  - Figs. 16-18: the densities of the three rules' values (Sec. 4, eqs. 8-10) for correct
//    and incorrect nearest matches, and the share of each that each rule rejects.
// Each setting is scored three ways: the nearest neighbour over the database of frames within
// the baseline (the paper's), over single frame pairs, and over frame pairs 1 m to the
// baseline apart.

#include <cstdint>
#include <cstdio>
#include <string>

#include "omnivert/describe/descriptor.hpp"
#include "omnivert/eval/descriptor_study.hpp"

namespace omnivert::eval {

struct SensitivityStudyOptions {
  DescriptorOptions descriptor;  // the defaults each figure varies one setting of
  double max_baseline = 2.0;     // [m]: frame pairs 1 m to this apart make the third score
  std::uint64_t seed = 1;        // of the image noise (Fig. 14)
};

// Runs Figs. 13-18 on `set` and writes into the folder out_dir (which must exist)
// sensitivity_{clip,noise,bins}.{csv,png}, rule{1,2,3}_pdf.{csv,png} and rules.csv. A line per
// setting goes to `report` (none when null).
void run_sensitivity_study(const StudySet& set,
                           const SensitivityStudyOptions& options,
                           const std::string& out_dir,
                           std::FILE* report);

}  // namespace omnivert::eval
