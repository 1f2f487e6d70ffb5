#include "buckle/continuation/interrupt.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace buckle::continuation {

Interrupt Interrupt::after(double seconds) {
  Interrupt i;
  if (std::isfinite(seconds)) {
    // Clamp far-future limits: Clock::duration overflows for limits beyond ~292 years.
    const double capped = std::min(std::max(seconds, 0.0), 1e9);
    i.setDeadline(Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(capped)),
                  seconds);
  }
  return i;
}

Interrupt &Interrupt::setDeadline(Clock::time_point deadline, double seconds) {
  hasDeadline_ = true;
  deadline_ = deadline;
  start_ = Clock::now();
  seconds_ = seconds;
  kept_ = std::make_shared<std::atomic<Clock::rep>>(0);  // a new deadline: its own copies
  return *this;
}

void Interrupt::keepBeforeDeadline(double seconds) const {
  if (!hasDeadline_ || !(seconds > 0.0)) return;
  const Clock::rep ticks =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(std::min(seconds, 1e9))).count();
  Clock::rep now = kept_->load(std::memory_order_relaxed);
  while (ticks > now && !kept_->compare_exchange_weak(now, ticks, std::memory_order_relaxed)) {
  }
}

Interrupt &Interrupt::watch(const std::atomic<bool> *flag, std::string what) {
  flag_ = flag;
  flagWhat_ = std::move(what);
  return *this;
}

std::string Interrupt::describe() const {
  switch (reason()) {
    case Reason::None: return "";
    case Reason::Flag: return flagWhat_;
    case Reason::TimeLimit: {
      std::ostringstream os;
      os << "time limit of " << seconds_ << " s reached";
      // The deadline moved before the limit by the room kept for writing (keepBeforeDeadline):
      // say when computing stopped, not only the limit the user set.
      const double stopped =
          std::chrono::duration<double>(deadline_ - Clock::duration(kept_->load(std::memory_order_relaxed)) - start_)
              .count();
      if (stopped > 0.0 && stopped < 0.9 * seconds_) {
        os.precision(3);
        os << " (computing stopped at " << stopped << " s, the rest of the limit kept for writing the results)";
      }
      return os.str();
    }
  }
  return "";
}

double Interrupt::secondsLeft() const {
  if (!hasDeadline_) return std::numeric_limits<double>::infinity();
  return std::chrono::duration<double>(deadline_ - Clock::duration(kept_->load(std::memory_order_relaxed)) -
                                       Clock::now())
      .count();
}

}  // namespace buckle::continuation
