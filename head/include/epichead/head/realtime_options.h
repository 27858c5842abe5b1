#pragma once
// Scheduling of the onboard loop's threads when vision runs on its own (VisionThreads::Thread):
// which CPU each is pinned to and its real-time priority. A request the system refuses (no
// CAP_SYS_NICE, an rtprio limit of 0, no such CPU) is no error: the thread keeps the normal
// policy and the run's summary says what each thread got (docs/head.md, "Threads and deadlines").
namespace epichead::head {

struct RealtimeOptions {
  int control_cpu = -1, vision_cpu = -1;  // pin to this CPU (-1: leave to the scheduler)
  int control_priority = 0;               // SCHED_FIFO priority 1..99 of the control thread (0: normal)
  int vision_priority = 0;                // the same for the vision worker (below the control thread's)
  bool lock_memory = false;               // mlockall: no page faults on the control thread after start-up
};

}  // namespace epichead::head
