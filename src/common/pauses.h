// common: notices when this process was not running for a while: stopped
// and continued (Ctrl-Z and fg, kill -STOP and -CONT) or the machine
// asleep. A timing that spans such a pause measures the pause, not the
// work, and is left out of decisions made from speed (rl/speed_tuner.h).
#ifndef MIMIC2D_COMMON_PAUSES_H_
#define MIMIC2D_COMMON_PAUSES_H_

#include <cstdint>

namespace m2d {

struct PauseMark {
  int64_t continues = 0;  // SIGCONTs this process has received
  // CLOCK_BOOTTIME - CLOCK_MONOTONIC (s): how long the machine has slept.
  double asleep_s = 0.0;
};

// Where the counts stand now. The first call installs a SIGCONT handler
// that counts (unless the program has its own); stopping and continuing
// work as before, since the kernel continues a process whatever its
// handler.
PauseMark MarkPauses();

// Whether the process was continued after a stop, or the machine slept
// more than `kMinSleepS`, between two marks.
constexpr double kMinSleepS = 0.1;
bool PausedBetween(const PauseMark& before, const PauseMark& after);

}  // namespace m2d

#endif  // MIMIC2D_COMMON_PAUSES_H_
