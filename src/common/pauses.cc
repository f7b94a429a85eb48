#include "common/pauses.h"

#include <signal.h>
#include <time.h>

#include <atomic>
#include <mutex>

namespace m2d {
namespace {

// Written by the handler on whichever thread receives the signal: only a
// lock-free atomic is safe there.
std::atomic<int64_t> num_continues{0};
static_assert(std::atomic<int64_t>::is_always_lock_free);

void CountContinue(int /*signal*/) {
  num_continues.fetch_add(1, std::memory_order_relaxed);
}

void InstallContinueCounter() {
  struct sigaction current = {};
  if (sigaction(SIGCONT, nullptr, &current) != 0) return;
  // A program that handles SIGCONT itself keeps its handler (pauses are
  // then only seen as the machine's sleep).
  if (current.sa_handler != SIG_DFL || (current.sa_flags & SA_SIGINFO)) return;
  struct sigaction counter = {};
  counter.sa_handler = CountContinue;
  sigemptyset(&counter.sa_mask);
  counter.sa_flags = SA_RESTART;  // interrupted system calls resume
  sigaction(SIGCONT, &counter, nullptr);
}

double Seconds(clockid_t clock) {
  timespec t = {};
  clock_gettime(clock, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace

PauseMark MarkPauses() {
  static std::once_flag installed;
  std::call_once(installed, InstallContinueCounter);
  PauseMark mark;
  mark.continues = num_continues.load(std::memory_order_relaxed);
  // Both clocks count from boot; only the boot clock goes on while the
  // machine is suspended.
  mark.asleep_s = Seconds(CLOCK_BOOTTIME) - Seconds(CLOCK_MONOTONIC);
  return mark;
}

bool PausedBetween(const PauseMark& before, const PauseMark& after) {
  return after.continues != before.continues ||
         after.asleep_s - before.asleep_s > kMinSleepS;
}

}  // namespace m2d
