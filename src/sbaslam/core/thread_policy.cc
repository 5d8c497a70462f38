#include "sbaslam/core/thread_policy.h"

#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <thread>

namespace sbaslam {

bool set_thread_policy(pthread_t thread, int policy) {
  sched_param param{};
  param.sched_priority = 0;
  return pthread_setschedparam(thread, policy, &param) == 0;
}

int thread_policy(pthread_t thread) {
  int policy = -1;
  sched_param param{};
  if (pthread_getschedparam(thread, &policy, &param) != 0) return -1;
  return policy;
}

bool can_toggle_idle_policy() {
  bool can = false;
  std::thread probe([&can] {
    can = set_thread_policy(pthread_self(), SCHED_IDLE) &&
          set_thread_policy(pthread_self(), SCHED_OTHER);
  });
  probe.join();
  return can;
}

bool lower_current_thread_priority(int steps) {
  // Linux keeps a nice value per thread.
  const auto tid = static_cast<id_t>(syscall(SYS_gettid));
  return setpriority(PRIO_PROCESS, tid, getpriority(PRIO_PROCESS, tid) + steps) == 0;
}

}  // namespace sbaslam
