#pragma once
// Linux scheduling policies of the helper threads (local mapping, loop closing). While tracking
// extracts features they run under SCHED_IDLE, so that extraction's threads get both cores;
// otherwise under SCHED_OTHER, so that other processes cannot starve them. Leaving SCHED_IDLE
// needs CAP_SYS_NICE or RLIMIT_NICE >= 20; where the process cannot, a helper runs at a raised
// nice value throughout instead.

#include <pthread.h>

namespace sbaslam {

bool set_thread_policy(pthread_t thread, int policy);
// The thread's policy (SCHED_OTHER, SCHED_IDLE, ...), or -1 if it cannot be read.
int thread_policy(pthread_t thread);
// Whether a thread of this process can enter SCHED_IDLE and leave it again, tried on a throwaway
// thread (which takes a policy it could not leave with it).
bool can_toggle_idle_policy();
// Raises the calling thread's nice value by `steps` (threads it starts later inherit it); false
// if it could not.
bool lower_current_thread_priority(int steps);

}  // namespace sbaslam
