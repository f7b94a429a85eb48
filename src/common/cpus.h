// common: how many CPUs this process may run on, and thread counts capped
// at it.
#ifndef MIMIC2D_COMMON_CPUS_H_
#define MIMIC2D_COMMON_CPUS_H_

#include <string>

namespace m2d {

// The CPUs in this process's affinity mask (taskset, a container's cpuset),
// else the machine's; at least 1.
int UsableCpus();

// `threads` capped at `cpus`, with a warning naming `setting` when capped:
// more threads than CPUs only time-slice (500 LibTorch threads trained at
// 57 samples/s on 2 CPUs, against about 5k with 2).
int CapThreadsAtCpus(int threads, int cpus, const std::string& setting);

}  // namespace m2d

#endif  // MIMIC2D_COMMON_CPUS_H_
