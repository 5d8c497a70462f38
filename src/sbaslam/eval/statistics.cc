#include "sbaslam/eval/statistics.h"

#include <algorithm>
#include <cmath>

#include "sbaslam/core/error.h"

namespace sbaslam::eval {

ErrorStatistics compute_statistics(const std::vector<double>& errors) {
  if (errors.empty()) fail("no errors to compute statistics of");
  for (std::size_t i = 0; i < errors.size(); ++i)
    if (!std::isfinite(errors[i])) fail("error {} is not finite ({})", i, errors[i]);

  ErrorStatistics stats;
  stats.n = errors.size();
  const double n = static_cast<double>(errors.size());
  double sum = 0.0;
  for (double e : errors) {
    sum += e;
    stats.sse += e * e;
  }
  stats.mean = sum / n;
  stats.rmse = std::sqrt(stats.sse / n);
  double squared_deviation = 0.0;
  for (double e : errors) squared_deviation += (e - stats.mean) * (e - stats.mean);
  stats.std = std::sqrt(squared_deviation / n);

  std::vector<double> sorted = errors;
  std::sort(sorted.begin(), sorted.end());
  stats.min = sorted.front();
  stats.max = sorted.back();
  const std::size_t mid = sorted.size() / 2;
  stats.median = sorted.size() % 2 == 1 ? sorted[mid] : 0.5 * (sorted[mid - 1] + sorted[mid]);
  return stats;
}

}  // namespace sbaslam::eval
