// Timings in milliseconds, the one copy of these clocks: CPU time (what one scan costs, whatever other
// threads do) and wall time since a start (the per-stage timers).
#pragma once

#include <time.h>

#include <chrono>
#include <ctime>

namespace hglasm {

/// CPU time of the calling thread (process CPU where POSIX thread clocks are missing).
inline double threadCpuMs() {
#if defined(CLOCK_THREAD_CPUTIME_ID)
  timespec now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return now.tv_sec * 1e3 + now.tv_nsec * 1e-6;
#else
  return 1e3 * static_cast<double>(std::clock()) / CLOCKS_PER_SEC;
#endif
}

/// CPU time of the whole process (bag decompression may run on other threads).
inline double processCpuMs() { return 1e3 * static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

/// Wall milliseconds on the monotonic clock since `start`.
inline double millisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace hglasm
