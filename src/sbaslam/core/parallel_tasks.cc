#include "sbaslam/core/parallel_tasks.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <opencv2/core/utility.hpp>

namespace sbaslam {

void run_tasks_in_parallel(const std::vector<std::function<void()>>& tasks) {
  std::atomic<std::size_t> next{0};
  std::mutex error_mutex;
  std::exception_ptr error;
  const auto drain = [&](const cv::Range&) {
    for (std::size_t k = next++; k < tasks.size(); k = next++) {
      try {
        tasks[k]();
      } catch (...) {
        const std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
      }
    }
  };
  const int threads = std::max(1, std::min(cv::getNumThreads(), static_cast<int>(tasks.size())));
  if (threads == 1) {
    drain(cv::Range(0, 1));
  } else {
    cv::parallel_for_(cv::Range(0, threads), drain, threads);
  }
  if (error) std::rethrow_exception(error);
}

}  // namespace sbaslam
