#include "sbaslam/eval/association.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "sbaslam/core/error.h"

namespace sbaslam::eval {
namespace {

struct MatchedIds {
  std::vector<std::size_t> first;
  std::vector<std::size_t> second;
};

// evo's matching_time_indices: offset added to the second list, first argmin kept if close.
MatchedIds match_time_indices(const std::vector<double>& stamps_1,
                              const std::vector<double>& stamps_2, double max_diff,
                              double offset_2) {
  std::vector<double> shifted(stamps_2.size());
  for (std::size_t i = 0; i < stamps_2.size(); ++i) shifted[i] = stamps_2[i] + offset_2;
  MatchedIds ids;
  for (std::size_t i = 0; i < stamps_1.size(); ++i) {
    std::size_t best = 0;
    double best_diff = std::abs(shifted[0] - stamps_1[i]);
    for (std::size_t j = 1; j < shifted.size(); ++j) {
      const double diff = std::abs(shifted[j] - stamps_1[i]);
      if (diff < best_diff) {
        best_diff = diff;
        best = j;
      }
    }
    if (best_diff <= max_diff) {
      ids.first.push_back(i);
      ids.second.push_back(best);
    }
  }
  return ids;
}

void require_valid(const PoseSeries& series, const char* role) {
  if (series.size() == 0) fail("the {} trajectory has no poses", role);
  if (series.stamps.size() != series.poses.size())
    fail("the {} trajectory has {} stamps but {} poses", role, series.stamps.size(),
         series.poses.size());
  for (std::size_t i = 0; i < series.size(); ++i) {
    if (!std::isfinite(series.stamps[i]) || !series.poses[i].allFinite())
      fail("the {} trajectory holds a NaN or infinite value at pose {}", role, i);
  }
}

void require_time_overlap(const PoseSeries& reference, const PoseSeries& estimate,
                          const AssociationSettings& settings) {
  const auto [ref_min, ref_max] =
      std::minmax_element(reference.stamps.begin(), reference.stamps.end());
  const auto [est_min, est_max] =
      std::minmax_element(estimate.stamps.begin(), estimate.stamps.end());
  const double est_begin = *est_min + settings.t_offset;
  const double est_end = *est_max + settings.t_offset;
  if (est_begin > *ref_max + settings.t_max_diff || est_end < *ref_min - settings.t_max_diff)
    fail(
        "no overlap in time: the reference spans [{}, {}] s, the estimate [{}, {}] s (with "
        "--t-offset {})",
        *ref_min, *ref_max, est_begin, est_end, settings.t_offset);
}

}  // namespace

PoseSeries select_poses(const PoseSeries& series, const std::vector<std::size_t>& ids) {
  PoseSeries selected;
  selected.stamps.reserve(ids.size());
  selected.poses.reserve(ids.size());
  for (std::size_t id : ids) {
    selected.stamps.push_back(series.stamps.at(id));
    selected.poses.push_back(series.poses.at(id));
  }
  return selected;
}

AssociatedSeries associate_by_time(const PoseSeries& reference, const PoseSeries& estimate,
                                   const AssociationSettings& settings) {
  require_valid(reference, "reference");
  require_valid(estimate, "estimate");
  if (!std::isfinite(settings.t_max_diff) || settings.t_max_diff < 0.0)
    fail("t-max-diff must be a finite, non-negative number of seconds (got {})",
         settings.t_max_diff);
  if (!std::isfinite(settings.t_offset))
    fail("t-offset must be a finite number of seconds (got {})", settings.t_offset);
  require_time_overlap(reference, estimate, settings);

  AssociatedSeries result;
  const bool estimate_longer = estimate.size() > reference.size();
  if (estimate_longer) {
    const MatchedIds ids = match_time_indices(reference.stamps, estimate.stamps,
                                              settings.t_max_diff, settings.t_offset);
    result.reference_ids = ids.first;
    result.estimate_ids = ids.second;
  } else {
    const MatchedIds ids = match_time_indices(estimate.stamps, reference.stamps,
                                              settings.t_max_diff, -settings.t_offset);
    result.estimate_ids = ids.first;
    result.reference_ids = ids.second;
  }
  if (result.reference_ids.empty())
    fail("no matching timestamps within t-max-diff {} s (t-offset {} s)", settings.t_max_diff,
         settings.t_offset);
  result.reference = select_poses(reference, result.reference_ids);
  result.estimate = select_poses(estimate, result.estimate_ids);
  return result;
}

AssociatedSeries associate_by_index(const PoseSeries& reference, const PoseSeries& estimate) {
  require_valid(reference, "reference");
  require_valid(estimate, "estimate");
  if (reference.size() != estimate.size())
    fail(
        "the reference has {} poses but the estimate {}: KITTI files are paired row by row and "
        "need the same length",
        reference.size(), estimate.size());
  AssociatedSeries result;
  result.reference = reference;
  result.estimate = estimate;
  result.reference_ids.resize(reference.size());
  std::iota(result.reference_ids.begin(), result.reference_ids.end(), std::size_t{0});
  result.estimate_ids = result.reference_ids;
  return result;
}

}  // namespace sbaslam::eval
