#include "omnivert/match/matcher.hpp"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace omnivert {
namespace {

// Descriptors at exactly known distances from A = e_0: B_j = cos(t_j) e_0 + sin(t_j) e_{j+1}
// has |A - B_j| = sqrt(2 - 2 cos t_j) = d_j.
struct KnownDistances {
  DescriptorMatrix a;
  DescriptorMatrix b;
};

KnownDistances make_known(const std::vector<double>& d, int dim = kPaperDescriptorSize) {
  KnownDistances k;
  k.a = DescriptorMatrix::Zero(1, dim);
  k.a(0, 0) = 1.0f;
  k.b = DescriptorMatrix::Zero(static_cast<Eigen::Index>(d.size()), dim);
  for (std::size_t j = 0; j < d.size(); ++j) {
    const double c = 1.0 - d[j] * d[j] / 2.0;
    k.b(static_cast<Eigen::Index>(j), 0) = static_cast<float>(c);
    k.b(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(j + 1)) =
        static_cast<float>(std::sqrt(1.0 - c * c));
  }
  return k;
}

MatchResult match_one(const std::vector<double>& d, MatchOptions o = {}) {
  const KnownDistances k = make_known(d);
  Matcher m(o);
  std::vector<MatchResult> r;
  m.match(k.a, k.b, &r);
  EXPECT_EQ(r.size(), 1u);
  return r[0];
}

// A paper-like descriptor: non-negative, unit length per 32-bin histogram, clipped at 0.1,
// renormalised (Sec. 3.3).
DescriptorMatrix random_descriptors(int n, std::mt19937& rng, int dim = kPaperDescriptorSize) {
  std::exponential_distribution<float> e(1.0f);
  DescriptorMatrix d(n, dim);
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < dim; ++k) d(i, k) = e(rng);
    d.row(i).normalize();
    d.row(i) = d.row(i).cwiseMin(0.1f);
    d.row(i).normalize();
  }
  return d;
}

TEST(MatchOptions, Validation) {
  std::string error;
  EXPECT_TRUE(MatchOptions{}.IsValid(&error));
  MatchOptions o;
  o.f2 = 1.5;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("F2"), std::string::npos);
  o = {};
  o.f3 = 0.0;
  EXPECT_FALSE(o.IsValid(&error));
  o = {};
  o.f1 = -1.0;
  EXPECT_FALSE(o.IsValid(&error));
  o = {};
  o.f1 = std::nan("");
  EXPECT_FALSE(o.IsValid(&error));
  o = {};
  o.partial_area_scale = 0.5;  // below 1 it would shrink every distance
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("partial-area"), std::string::npos);
  o.partial_area_scale = INFINITY;
  EXPECT_FALSE(o.IsValid(&error));
  o.partial_area_scale = 2.0;
  EXPECT_TRUE(o.IsValid(&error));
}

TEST(Matcher, KnownDistancesAreReproduced) {
  const std::vector<double> d = {0.57, 0.72, 0.74, 0.78, 0.83};
  const MatchResult r = match_one(d);
  EXPECT_EQ(r.best, 0);
  EXPECT_NEAR(r.min_distance, 0.57, 1e-5);
  EXPECT_NEAR(r.second_distance, 0.72, 1e-5);
  EXPECT_NEAR(r.mean_distance, 3.64 / 5.0, 1e-5);
}

// The paper's Table 1 example with Table 2's factors: B1 passes tests 1 and 3 and fails
// test 2, exactly as Sec. 4 says, provided <D_i> is the mean of all five distances
// (0.728; 0.75 * 0.728 = 0.546 < 0.57). With the minimum excluded from the mean ("all
// other descriptors": 0.7675; 0.75 * 0.7675 = 0.5756 >= 0.57) B1 would pass test 2.
TEST(Matcher, PaperTable1FailsTest2Only) {
  const std::vector<double> d = {0.57, 0.72, 0.74, 0.78, 0.83};
  EXPECT_EQ(match_one(d).verdict, MatchVerdict::kFailedTest2);
  MatchOptions only1;
  only1.use_test2 = only1.use_test3 = false;
  EXPECT_TRUE(match_one(d, only1).accepted());
  MatchOptions only3;
  only3.use_test1 = only3.use_test2 = false;
  EXPECT_TRUE(match_one(d, only3).accepted());  // 0.57 <= 0.8 * 0.72 = 0.576, narrowly
  MatchOptions only2;
  only2.use_test1 = only2.use_test3 = false;
  EXPECT_EQ(match_one(d, only2).verdict, MatchVerdict::kFailedTest2);
  // The other reading of the mean would accept: documented in docs/tracking.md.
  const double mean_of_others = (0.72 + 0.74 + 0.78 + 0.83) / 4.0;
  EXPECT_LE(0.57, 0.75 * mean_of_others);
  EXPECT_GT(0.57, 0.75 * (0.57 + 0.72 + 0.74 + 0.78 + 0.83) / 5.0);
}

TEST(Matcher, Test1RejectsFarNearest) {
  // min 1.1 > F1 = 1.05; test 2: 1.1 <= 0.75 * 1.725; test 3: 1.1 <= 0.8 * 1.9.
  const std::vector<double> d = {1.1, 1.9, 1.95, 1.95};
  EXPECT_EQ(match_one(d).verdict, MatchVerdict::kFailedTest1);
  MatchOptions o;
  o.f1 = 1.2;
  EXPECT_TRUE(match_one(d, o).accepted());
}

TEST(Matcher, Test3RejectsCloseSecond) {
  // test 3: 0.5 > 0.8 * 0.6 = 0.48; tests 1 and 2 pass (0.75 * 1.06 = 0.795).
  const std::vector<double> d = {0.6, 0.5, 1.4, 1.4, 1.4};
  const MatchResult r = match_one(d);
  EXPECT_EQ(r.best, 1);
  EXPECT_EQ(r.verdict, MatchVerdict::kFailedTest3);
  MatchOptions o;
  o.f3 = 0.85;  // 0.5 <= 0.51
  EXPECT_TRUE(match_one(d, o).accepted());
}

TEST(Matcher, ClearMatchAccepted) {
  const MatchResult r = match_one({1.3, 1.2, 0.2, 1.25});
  EXPECT_EQ(r.best, 2);
  EXPECT_TRUE(r.accepted());
}

TEST(Matcher, SmallCandidateSets) {
  // None: no candidates.
  {
    const KnownDistances k = make_known({});
    Matcher m;
    std::vector<MatchResult> r;
    m.match(k.a, k.b, &r);
    ASSERT_EQ(r.size(), 1u);
    EXPECT_EQ(r[0].verdict, MatchVerdict::kNoCandidates);
    EXPECT_EQ(r[0].best, -1);
  }
  // One: the mean is the minimum; test 2 rejects any non-zero distance.
  EXPECT_EQ(match_one({0.1}).verdict, MatchVerdict::kFailedTest2);
  MatchOptions no2;
  no2.use_test2 = false;
  EXPECT_TRUE(match_one({0.1}, no2).accepted());  // test 3 vacuous, test 1 passes
  // Two: test 2 is min <= F2 / (2 - F2) * Smin = 0.6 * Smin.
  EXPECT_EQ(match_one({0.5, 0.8}).verdict, MatchVerdict::kFailedTest2);  // 0.5 > 0.48
  EXPECT_TRUE(match_one({0.5, 0.9}).accepted());                         // 0.5 <= 0.54
  // Tie between the two nearest: the lowest index, rejected by test 3.
  const MatchResult tie = match_one({0.3, 0.3, 1.5, 1.5});
  EXPECT_EQ(tie.verdict, MatchVerdict::kFailedTest3);
}

TEST(Matcher, EmptyQuery) {
  Matcher m;
  std::vector<MatchResult> r(3);
  DescriptorMatrix a(0, 192), b = DescriptorMatrix::Zero(4, 192);
  m.match(a, b, &r);
  EXPECT_TRUE(r.empty());
}

// The fast path (one matrix product, float) against the definition (double, term by term).
TEST(Matcher, AgreesWithBruteForceOnRandomInputs) {
  std::mt19937 rng(7);
  Matcher m;
  std::vector<MatchResult> fast;
  int accepted = 0, compared = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int na = std::uniform_int_distribution<int>(0, 45)(rng);
    const int nb = std::uniform_int_distribution<int>(0, 45)(rng);
    DescriptorMatrix a = random_descriptors(na, rng);
    const DescriptorMatrix b = random_descriptors(nb, rng);
    // Make some queries noisy copies of candidates so that all verdicts occur.
    std::normal_distribution<float> noise(0.0f, 0.01f);
    for (int i = 0; i < na && nb > 0; i += 2) {
      const int j = std::uniform_int_distribution<int>(0, nb - 1)(rng);
      for (int k = 0; k < a.cols(); ++k) a(i, k) = b(j, k) + noise(rng);
      a.row(i).normalize();
    }
    m.match(a, b, &fast);
    const auto ref = match_brute_force(MatchOptions{}, a, b);
    const auto dist = m.last_distances();
    ASSERT_EQ(fast.size(), ref.size());
    for (int i = 0; i < na; ++i) {
      for (int j = 0; j < nb; ++j) {
        const double exact = (a.row(i).cast<double>() - b.row(j).cast<double>()).norm();
        ASSERT_NEAR(dist(i, j), exact, 2e-4) << i << "," << j;
      }
      const MatchResult& f = fast[static_cast<std::size_t>(i)];
      const MatchResult& r = ref[static_cast<std::size_t>(i)];
      ++compared;
      if (nb == 0) {
        EXPECT_EQ(f.verdict, MatchVerdict::kNoCandidates);
        continue;
      }
      EXPECT_NEAR(f.min_distance, r.min_distance, 2e-4);
      EXPECT_NEAR(f.mean_distance, r.mean_distance, 2e-4);
      if (nb >= 2) {
        EXPECT_NEAR(f.second_distance, r.second_distance, 2e-4);
      }
      // Float rounding may swap a near-tie; everything else must agree exactly.
      if (r.second_distance - r.min_distance > 1e-3f) {
        EXPECT_EQ(f.best, r.best);
      }
      const bool near_boundary = std::abs(r.min_distance - 1.05) < 1e-3 ||
                                 std::abs(r.min_distance - 0.75 * r.mean_distance) < 1e-3 ||
                                 std::abs(r.min_distance - 0.8 * r.second_distance) < 1e-3;
      if (!near_boundary) {
        EXPECT_EQ(f.verdict, r.verdict) << "query " << i;
      }
      accepted += r.accepted();
    }
  }
  EXPECT_GT(accepted, 500);  // the random sets do exercise acceptance
  EXPECT_GT(compared, 3000);
}

// MatchOptions::partial_area_scale on known geometry: a candidate equal to the query but in
// one area (an occluder there: that area's histograms replaced) is at D^2 = d_k^2 by eq. (6)
// and at 0 with the occluder-tolerant distance; a candidate that differs evenly in all three
// areas keeps its eq. (6) distance (no area holds more than half of D^2 at s = 2).
TEST(Matcher, OneChangedAreaIsLeftOutAndEvenChangesAreNot) {
  std::mt19937 rng(3);
  const DescriptorMatrix a = random_descriptors(1, rng);
  DescriptorMatrix b(2, a.cols());
  const Eigen::Index w = a.cols() / 3;
  b.row(0) = a.row(0);
  b.row(0).segment(0, w) = random_descriptors(1, rng, static_cast<int>(w)).row(0) *
                           a.row(0).segment(0, w).norm();  // the inner area replaced
  b.row(1) = a.row(0);
  for (Eigen::Index k = 0; k < 3; ++k) b(1, k * w) += 0.05f;  // the same change in each area
  const double d_area = (a.row(0) - b.row(0)).norm();
  const double d_even = (a.row(0) - b.row(1)).norm();
  ASSERT_GT(d_area, 0.3);

  MatchOptions paper, tolerant;
  tolerant.partial_area_scale = 2.0;
  Matcher m_paper(paper), m_tolerant(tolerant);
  EXPECT_NEAR(m_paper.compute_distances(a, b)(0, 0), d_area, 1e-5);
  const auto d = m_tolerant.compute_distances(a, b);
  EXPECT_NEAR(d(0, 0), 0.0, 1e-3);
  EXPECT_NEAR(d(0, 1), d_even, 1e-5);
  EXPECT_NEAR(std::sqrt(descriptor_distance_sq(tolerant, a.row(0), b.row(0))), 0.0, 1e-3);
  EXPECT_NEAR(std::sqrt(descriptor_distance_sq(tolerant, a.row(0), b.row(1))), d_even, 1e-5);
  EXPECT_NEAR(std::sqrt(descriptor_distance_sq(paper, a.row(0), b.row(0))), d_area, 1e-5);
  // Two areas changed: the third alone cannot decide, s (d_1^2 + ... - max) > sum for s = 2
  // only when one area dominates; here the two changed areas share the distance.
  DescriptorMatrix c = a;
  c(0, 0) += 0.3f;
  c(0, w) += 0.3f;
  EXPECT_NEAR(m_tolerant.compute_distances(a, c)(0, 0), (a.row(0) - c.row(0)).norm(), 1e-5);
}

// An occluder-tolerant fast path against the reference term by term, on random sets in which
// every second query row is a candidate with part of it replaced (`replace(row, rng)`, the
// part's scale kept). Returns how many distances took a tolerant branch.
template <typename Replace>
int expect_fast_path_agrees(const MatchOptions& o, std::mt19937& rng, int trials, Replace replace) {
  Matcher m(o);
  std::vector<MatchResult> fast;
  int partial = 0;
  for (int trial = 0; trial < trials; ++trial) {
    const int na = std::uniform_int_distribution<int>(1, 40)(rng);
    const int nb = std::uniform_int_distribution<int>(2, 40)(rng);
    DescriptorMatrix a = random_descriptors(na, rng);
    const DescriptorMatrix b = random_descriptors(nb, rng);
    for (int i = 0; i < na; i += 2) {
      const int j = std::uniform_int_distribution<int>(0, nb - 1)(rng);
      a.row(i) = b.row(j);
      replace(a.row(i), rng);
    }
    m.match(a, b, &fast);
    const auto ref = match_brute_force(o, a, b);
    const auto dist = m.last_distances();
    for (int i = 0; i < na; ++i) {
      for (int j = 0; j < nb; ++j) {
        const double full = (a.row(i) - b.row(j)).norm();
        const double exact = std::sqrt(descriptor_distance_sq(o, a.row(i), b.row(j)));
        // Single precision: 1e-7 on d^2, 3e-4 on d near an exact copy (the square root).
        EXPECT_NEAR(dist(i, j) * dist(i, j), exact * exact, 1e-5) << i << "," << j;
        partial += exact < full - 1e-3;
      }
      const MatchResult& f = fast[static_cast<std::size_t>(i)];
      const MatchResult& r = ref[static_cast<std::size_t>(i)];
      EXPECT_NEAR(f.min_distance, r.min_distance, 1e-3);
      EXPECT_NEAR(f.second_distance, r.second_distance, 1e-3);
      EXPECT_NEAR(f.mean_distance, r.mean_distance, 1e-3);
      if (r.second_distance - r.min_distance > 1e-3f) {
        EXPECT_EQ(f.best, r.best);
      }
    }
  }
  return partial;
}

// Replaces `width` columns from `at` by random ones of the same norm.
void replace_part(Eigen::Ref<Eigen::RowVectorXf> row,
                  Eigen::Index at,
                  int width,
                  std::mt19937& rng) {
  const float norm = row.segment(at, width).norm();
  row.segment(at, width) = random_descriptors(1, rng, width).row(0) * norm;
}

// The occluder-tolerant fast path (three matrix products) against the reference.
TEST(Matcher, TheOccluderTolerantDistanceAgreesWithBruteForce) {
  std::mt19937 rng(11);
  MatchOptions o;
  o.partial_area_scale = 2.0;
  const int partial = expect_fast_path_agrees(o, rng, 50, [](auto row, std::mt19937& g) {
    replace_part(row, std::uniform_int_distribution<Eigen::Index>(0, 2)(g) * 64, 64, g);
  });
  EXPECT_GT(partial, 100);  // the one-area copies do take the tolerant branch
}

// MatchOptions::partial_side_scale on known geometry: a candidate equal to the query but on
// one side of the line (a person there: that side's three halves replaced) is at 0, alone or
// with the area rule; one changed in one area only is left out by the area rule as before.
TEST(Matcher, OneChangedSideIsLeftOut) {
  std::mt19937 rng(5);
  const DescriptorMatrix a = random_descriptors(1, rng);
  const Eigen::Index w = a.cols() / 6;  // one half: H_kL or H_kR
  DescriptorMatrix b = a;
  for (Eigen::Index k = 0; k < 3; ++k) {  // the right halves replaced
    const Eigen::Index at = (2 * k + 1) * w;
    b.row(0).segment(at, w) =
        random_descriptors(1, rng, static_cast<int>(w)).row(0) * a.row(0).segment(at, w).norm();
  }
  ASSERT_GT((a.row(0) - b.row(0)).norm(), 0.5);
  MatchOptions sides, both, area;
  sides.partial_side_scale = 2.0;
  both.partial_side_scale = 2.0;
  both.partial_area_scale = 2.0;
  area.partial_area_scale = 2.0;
  for (const MatchOptions& o : {sides, both}) {
    Matcher m(o);
    EXPECT_NEAR(m.compute_distances(a, b)(0, 0), 0.0, 1e-3);
    EXPECT_NEAR(std::sqrt(descriptor_distance_sq(o, a.row(0), b.row(0))), 0.0, 1e-3);
  }
  // Every area changed: the area rule alone keeps most of the distance.
  EXPECT_GT(Matcher(area).compute_distances(a, b)(0, 0), 0.5 * (a.row(0) - b.row(0)).norm());
  // A change on both sides evenly: sqrt(2 min(L, R)) equals the full distance, not less.
  DescriptorMatrix c = a;
  c(0, 0) += 0.2f;
  c(0, w) += 0.2f;
  EXPECT_NEAR(Matcher(sides).compute_distances(a, c)(0, 0), (a.row(0) - c.row(0)).norm(), 1e-4);
}

// The side-tolerant fast path (six matrix products) against the reference, alone and with
// the area rule.
TEST(Matcher, TheSideTolerantDistanceAgreesWithBruteForce) {
  std::mt19937 rng(13);
  for (const double area_scale : {0.0, 2.0}) {
    MatchOptions o;
    o.partial_area_scale = area_scale;
    o.partial_side_scale = 2.0;
    const int partial = expect_fast_path_agrees(o, rng, 30, [](auto row, std::mt19937& g) {
      const int side = std::uniform_int_distribution<int>(0, 1)(g);
      for (Eigen::Index k = 0; k < 3; ++k) replace_part(row, (2 * k + side) * 32, 32, g);
    });
    EXPECT_GT(partial, 100) << "area scale " << area_scale;  // the one-side copies do
  }
}

}  // namespace
}  // namespace omnivert
