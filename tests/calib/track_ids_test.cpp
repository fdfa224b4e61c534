// Renaming a run's tracks (track_ids.hpp): the parts of split tracks, the chains of joined
// pieces.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <vector>

#include <Eigen/Dense>

#include "calib/batch_point.hpp"
#include "calib/synthetic_run.hpp"
#include "omnivert/calib/refinement.hpp"
#include "omnivert/calib/track_ids.hpp"
#include "omnivert/core/angles.hpp"
#include "synthetic_support.hpp"

namespace omnivert::calib {
namespace {

using test_support::nees;
using test_support::options_for;
using test_support::slip;
using test_support::truth_point;

// split_tracks cuts each track at its split frames, the parts under new ids: the same parts
// as the refinement's own split run.
TEST(TrackSplitting, SplitTracksRebuildsTheRefinementsParts) {
  CalibrationRun run;
  run.frames.resize(10);
  for (int k = 0; k < 10; ++k) {
    run.frames[k].observations.push_back({3, 0.1 * k});
    if (k >= 2) run.frames[k].observations.push_back({8, -0.1 * k});
  }
  std::map<int, int> origin;
  const CalibrationRun out = split_tracks(run, {{3, 6}, {3, 4}, {8, 9}}, &origin);
  // Track 3: frames 0-3 keep id 3, 4-5 and 6-9 get new ids; track 8: 2-8 keep 8, 9 new.
  std::vector<int> id3, id8;
  for (int k = 0; k < 10; ++k) {
    id3.push_back(out.frames[k].observations[0].track_id);
    EXPECT_DOUBLE_EQ(out.frames[k].observations[0].beta, 0.1 * k);
    if (k >= 2) id8.push_back(out.frames[k].observations[1].track_id);
  }
  EXPECT_EQ(id3[0], 3);
  EXPECT_EQ(id3[3], 3);
  EXPECT_EQ(id3[4], id3[5]);
  EXPECT_EQ(id3[6], id3[9]);
  EXPECT_NE(id3[4], id3[6]);
  EXPECT_GT(id3[4], 8);
  EXPECT_GT(id3[6], 8);
  EXPECT_EQ(id8[0], 8);
  EXPECT_EQ(id8[6], 8);
  EXPECT_GT(id8[7], 8);
  EXPECT_NE(id8[7], id3[4]);
  EXPECT_NE(id8[7], id3[6]);
  EXPECT_EQ(origin.size(), 3u);
  EXPECT_EQ(origin.at(id3[4]), 3);
  EXPECT_EQ(origin.at(id3[6]), 3);
  EXPECT_EQ(origin.at(id8[7]), 8);
  EXPECT_EQ(split_tracks(run, {}).frames[5].observations[1].track_id, 8);
}

// A tracker that loses lines and finds them again under new ids (a new id with probability
// 0.1 per frame: pieces of ~10 frames). The refinement joins the pieces of each line
// (CalibrationOptions::association.join_pieces) and so reaches nearly the precision of the whole
// tracks. Seeds 69 and 90: with the Wald test alone, 2 and 4 joins were of two lines (a
// three-bearing piece has no depth and passed it at 0.00), and the refinement ended with NEES 46
// and 1547. Chains of joins are followed to the line's first piece; of two joins of one piece the
// last counts; a join of a piece to itself and one that closes a loop are left out, so every chain
// ends (the window reports joins by the tracker's ids, and a corridor zigzag run hung on
// (T, T)).
TEST(PiecesOfOneLine, JoinChainsEndAtTheFirstPiece) {
  // Taken from the last: 8 -> 7, 2 -> 5, 1 -> 3, (3, 3) left out, 3 -> 2; (1, 2) is a second
  // join of 2, left out. The chains: 1 -> 3 -> 2 -> 5.
  const std::map<int, int> r = join_roots({{1, 2}, {2, 3}, {3, 3}, {3, 1}, {5, 2}, {7, 8}});
  const std::map<int, int> expected = {{1, 5}, {2, 5}, {3, 5}, {8, 7}};
  EXPECT_EQ(r, expected);
  EXPECT_TRUE(join_roots({{4, 4}}).empty());
  // A loop: the last pair is kept, the one that would close the loop left out.
  const std::map<int, int> two = join_roots({{4, 6}, {6, 4}});
  EXPECT_EQ(two, (std::map<int, int>{{4, 6}}));
  // Without loops or repeats, plain chains.
  const std::map<int, int> chain = join_roots({{1, 2}, {2, 3}, {3, 4}});
  EXPECT_EQ(chain, (std::map<int, int>{{2, 1}, {3, 1}, {4, 1}}));
}

}  // namespace
}  // namespace omnivert::calib
