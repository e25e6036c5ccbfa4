// CPU time for the tools' timings (milliseconds).
#pragma once

#include <time.h>

namespace hglasm_odometry {

inline double cpuMs(clockid_t clock) {
  timespec now{};
  clock_gettime(clock, &now);
  return now.tv_sec * 1e3 + now.tv_nsec * 1e-6;
}

/// CPU time of the calling thread: what one scan costs, whatever other threads do.
inline double threadCpuMs() { return cpuMs(CLOCK_THREAD_CPUTIME_ID); }

/// CPU time of the whole process (bag decompression may run on other threads).
inline double processCpuMs() { return cpuMs(CLOCK_PROCESS_CPUTIME_ID); }

}  // namespace hglasm_odometry
