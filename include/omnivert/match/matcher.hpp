#pragma once
// Descriptor matching of Sec. 4: Euclidean distance between descriptors (eq. 6) and the
// paper's three acceptance tests (eqs. 8-10).
//
// For each query descriptor A_i (row i of `query`) the matcher finds the nearest candidate
// B_j (row j of `candidates`) and accepts it only if
//   test 1, eq. (8):  min D_i <= F1
//   test 2, eq. (9):  min D_i <= F2 * <D_i>      (<D_i> = mean of ALL N_B distances of A_i)
//   test 3, eq. (10): min D_i <= F3 * Smin D_i   (Smin D_i = second smallest distance)
//
// The mean of test 2 includes the minimum itself: eq. (9) defines <D_i> as the mean of D_i,
// and only that reading reproduces the paper's Table 1 example (B1 passes tests 1 and 3 and
// fails test 2); "the mean of all other descriptors" (minimum excluded) would let B1 pass test
// 2. See docs/tracking.md.
//
// Small candidate sets (the paper is silent):
//   N_B = 0: no match (MatchResult::best == -1).
//   N_B = 1: there is no second distance; test 3 is vacuous (Smin = +infinity) but test 2
//            has <D_i> = min D_i and rejects every non-zero distance. A lone candidate is
//            therefore never accepted: nothing measures its distinctiveness, and the paper
//            prefers a new entry to a false match (Sec. 9.1).
//   N_B = 2: all three tests are applied as written; test 2 then reads
//            min <= F2 / (2 - F2) * Smin = 0.6 Smin for F2 = 0.75, stricter than test 3.
// Ties (equal distances) go to the lowest candidate index; a tie between the two nearest
// means min == Smin, which test 3 rejects for F3 < 1.
//
// Distances are computed as sqrt(max(0, |a|^2 + |b|^2 - 2 a.b)) in single precision with one
// matrix product; for the paper's unit-length descriptors the absolute error is about 1e-6
// on d^2. A Matcher keeps its work space between calls: no allocation in steady state.

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "omnivert/describe/frame_features.hpp"

namespace omnivert {

struct MatchOptions {
  double f1 = 1.05;  // Table 2, eq. (8): absolute bound on the nearest distance
  double f2 = 0.75;  // Table 2, eq. (9): nearest vs mean distance
  double f3 = 0.8;   // Table 2, eq. (10): nearest vs second nearest distance
  // Switches for each test (all on in the paper); for measuring each rule's worth.
  bool use_test1 = true;
  bool use_test2 = true;
  bool use_test3 = true;
  // The occluder-tolerant distance; 0: eq. (6) as the paper has it. The descriptor's three
  // areas (Sec. 3: inner, middle and outer circle, columns in thirds) are compared apart,
  // d_k^2 the squared distance over area k's histograms, and
  //   D = sqrt(min(sum_k d_k^2, s (sum_k d_k^2 - max_k d_k^2)))
  // with s this scale (at least 1): where one area holds more than (s - 1) / s of the
  // squared distance, the other two decide. A person passing beside a line changes the
  // histograms of the areas it enters (the inner circle spans +-17 degrees of bearing at the
  // annulus's inner radius), not the others (docs/theory/matching.md#occluders).
  double partial_area_scale = 0.0;
  // The same for the line's two sides; 0: off. With L and R the squared distances over the
  // halves on each side of the line (all three areas' H_kL, and H_kR), the distance may also
  // be sqrt(s_side min(L, R)): a person walking beside a line changes the histograms on its
  // side only, whichever areas it enters. With both scales set, the least of the three forms.
  double partial_side_scale = 0.0;

  // True when the options are usable; otherwise false with the reason in *error.
  bool IsValid(std::string* error) const;
};

// Why a query was (not) matched. Tests are evaluated in order 1, 2, 3; the first that fails
// is reported.
enum class MatchVerdict {
  kAccepted,
  kNoCandidates,
  kFailedTest1,
  kFailedTest2,
  kFailedTest3,
};

const char* to_string(MatchVerdict v);

// The outcome for one query row.
struct MatchResult {
  int best = -1;  // index of the nearest candidate, -1 when there are none
  float min_distance = std::numeric_limits<float>::infinity();
  float second_distance = std::numeric_limits<float>::infinity();  // +inf when N_B < 2
  float mean_distance = std::numeric_limits<float>::infinity();    // over all N_B distances
  MatchVerdict verdict = MatchVerdict::kNoCandidates;
  bool accepted() const { return verdict == MatchVerdict::kAccepted; }
};

// Applies tests 1-3 (eqs. 8-10) to the summary statistics of one row of distances.
MatchVerdict apply_match_tests(const MatchOptions& options,
                               int num_candidates,
                               double min_distance,
                               double second_distance,
                               double mean_distance);

// The squared descriptor distance of eq. (6) between rows a and b, or its occluder-tolerant
// form (MatchOptions::partial_area_scale).
float descriptor_distance_sq(const MatchOptions& options,
                             const Eigen::Ref<const Eigen::RowVectorXf>& a,
                             const Eigen::Ref<const Eigen::RowVectorXf>& b);

// Computes distance matrices and applies the tests. Reuse one Matcher across frames: its
// buffers grow to the largest sizes seen and are then reused.
class Matcher {
 public:
  using ConstDescriptors = Eigen::Ref<const DescriptorMatrix>;
  // Row-major, so that each query's row of distances is contiguous.
  using DistanceMatrix = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  using DistanceView = Eigen::Block<const DistanceMatrix>;

  explicit Matcher(MatchOptions options = {});

  const MatchOptions& options() const { return options_; }

  // Fills `distances` (query.rows() x candidates.rows()) with eq. (6) distances. Both inputs
  // must have the same number of columns (asserted). The returned view stays valid until
  // the next call.
  DistanceView compute_distances(const ConstDescriptors& query, const ConstDescriptors& candidates);

  // For every query row, the nearest candidate and the verdict of tests 1-3. `results` is
  // resized to query.rows().
  void match(const ConstDescriptors& query,
             const ConstDescriptors& candidates,
             std::vector<MatchResult>* results);

  // Summary of one row of a distance matrix (min, second min, mean) and the tests' verdict.
  MatchResult evaluate_row(const Eigen::Ref<const Eigen::RowVectorXf>& row) const;

  // The distance matrix of the last compute_distances/match call.
  DistanceView last_distances() const { return DistanceView(distances_, 0, 0, rows_, cols_); }

 private:
  DistanceView partial_distances(const ConstDescriptors& query, const ConstDescriptors& candidates);
  DistanceView partial_side_distances(const ConstDescriptors& query,
                                      const ConstDescriptors& candidates);
  void block_distances_sq(const ConstDescriptors& query,
                          const ConstDescriptors& candidates,
                          Eigen::Index at,
                          Eigen::Index width,
                          Eigen::Block<DistanceMatrix> out);

  MatchOptions options_;
  // Work space with capacity; the live part is the top-left rows_ x cols_ corner.
  DistanceMatrix distances_;
  DistanceMatrix area_, worst_;  // the occluder-tolerant distance's: one area's d^2, the largest
  DistanceMatrix half_, left_, right_;  // with partial_side_scale: one half's d^2, each side's
  Eigen::VectorXf query_norms_;
  Eigen::VectorXf candidate_norms_;
  Eigen::Index rows_ = 0;
  Eigen::Index cols_ = 0;
};

// The plain reference: every distance by its definition (eq. 6, or the occluder-tolerant
// form term by term), double precision, and the tests applied to the sorted row. For tests of
// the fast path.
std::vector<MatchResult> match_brute_force(const MatchOptions& options,
                                           const DescriptorMatrix& query,
                                           const DescriptorMatrix& candidates);

}  // namespace omnivert
