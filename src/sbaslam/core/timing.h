#pragma once
// Summaries of per-frame or per-keyframe durations for timing.json and benchmark tables.

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <nlohmann/json.hpp>
#include <vector>

namespace sbaslam {

struct TimingSummary {
  double median = 0.0, p90 = 0.0, mean = 0.0, max = 0.0;
  std::size_t n = 0;
};

// Median and p90 by nearest rank on the sorted samples (median averages the middle two).
inline TimingSummary summarize(std::vector<double> samples) {
  TimingSummary s;
  s.n = samples.size();
  if (samples.empty()) return s;
  std::sort(samples.begin(), samples.end());
  const std::size_t n = samples.size();
  s.median = n % 2 ? samples[n / 2] : 0.5 * (samples[n / 2 - 1] + samples[n / 2]);
  s.p90 = samples[std::min(n - 1, static_cast<std::size_t>(0.9 * static_cast<double>(n)))];
  double sum = 0.0;
  for (double v : samples) sum += v;
  s.mean = sum / static_cast<double>(n);
  s.max = samples.back();
  return s;
}

inline nlohmann::json to_json(const TimingSummary& s) {
  return {{"median", s.median}, {"p90", s.p90}, {"mean", s.mean}, {"max", s.max}, {"n", s.n}};
}

class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  double elapsed_ms() const {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_)
        .count();
  }

 private:
  std::chrono::steady_clock::time_point start_;
};

}  // namespace sbaslam
