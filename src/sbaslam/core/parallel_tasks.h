#pragma once
// Runs a list of independent tasks on OpenCV's threads (its parallel framework: TBB in Debian's
// build), each thread taking the next task in list order until none is left. Given longest
// first, that is greedy list scheduling, within a task's length of the best split. The front end
// shares the two cores this way between both images' pyramid levels and the saliency inference
// (docs/RESULTS.md, "Session 17").
//
// OpenCV runs a parallel region opened inside another one serially, so OpenCV calls inside a
// task (cv::FAST, the dnn forward pass) stay on the task's thread and do not oversubscribe the
// cores. Each task must write only what no other task touches.

#include <functional>
#include <vector>

namespace sbaslam {

// Returns when every task has run; then rethrows the first exception a task threw (the others
// still run to the end).
void run_tasks_in_parallel(const std::vector<std::function<void()>>& tasks);

}  // namespace sbaslam
