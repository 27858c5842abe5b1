#pragma once
// Scheduling of the onboard loop's threads on Linux: pinning the calling thread to one CPU and
// asking for the real-time FIFO policy. Each returns a short note of what the thread got, for
// the run's summary; a refusal (no CAP_SYS_NICE, an RLIMIT_RTPRIO of 0, a CPU that does not
// exist) is no error: the thread then runs as it was, and the note says so.
#include <string>

namespace epichead::head {

// Pins the calling thread to `cpu` (>= 0; < 0 leaves it to the scheduler).
std::string pin_current_thread(int cpu);
// SCHED_FIFO at `priority` (1..99) for the calling thread; 0 leaves the normal policy.
std::string request_fifo(int priority);
// Locks the process's pages in memory (no page faults on the control thread after start-up).
std::string lock_memory();

}  // namespace epichead::head
