#include "realtime.h"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstring>

namespace epichead::head {

std::string pin_current_thread(int cpu) {
  if (cpu < 0) return "any cpu";
  if (cpu >= CPU_SETSIZE) return "cpu " + std::to_string(cpu) + " refused (no such cpu)";
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  if (const int rc = pthread_setaffinity_np(pthread_self(), sizeof set, &set); rc != 0)
    return "cpu " + std::to_string(cpu) + " refused (" + std::strerror(rc) + ")";
  return "cpu " + std::to_string(cpu);
}

std::string request_fifo(int priority) {
  if (priority <= 0) return "SCHED_OTHER";
  sched_param p{};
  p.sched_priority = priority;
  if (const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &p); rc != 0)
    return "SCHED_FIFO " + std::to_string(priority) + " refused (" + std::strerror(rc) +
           (rc == EPERM ? ": needs CAP_SYS_NICE or an rtprio limit in /etc/security/limits.conf" : "") +
           "), SCHED_OTHER";
  return "SCHED_FIFO " + std::to_string(priority);
}

std::string lock_memory() {
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0)
    return std::string("memory not locked (") + std::strerror(errno) + ")";
  return "memory locked";
}

}  // namespace epichead::head
