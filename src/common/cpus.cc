#include "common/cpus.h"

#include <sched.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <thread>

namespace m2d {

int UsableCpus() {
  cpu_set_t mask;
  CPU_ZERO(&mask);
  if (sched_getaffinity(0, sizeof(mask), &mask) == 0) {
    const int count = CPU_COUNT(&mask);
    if (count > 0) return count;
  }
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

int CapThreadsAtCpus(int threads, int cpus, const std::string& setting) {
  if (threads <= cpus) return threads;
  spdlog::warn("{} {} exceeds the {} CPU(s) this process may use; using {}",
               setting, threads, cpus, cpus);
  return cpus;
}

}  // namespace m2d
