// Stopping a long computation early, from outside: a wall-clock deadline and/or a flag that a
// signal handler or another thread sets. The loops of the core (continuation steps, location
// samples, the branch tree) and of the dynamics (integration steps) ask requested() once per
// iteration; a computation stopped this way keeps everything it computed and says why
// (StopReason::Interrupted, with describe() as its message). Copies share the flag, so one
// Interrupt can be handed to every stage of a run.
#pragma once

#include <atomic>
#include <chrono>
#include <memory>
#include <string>

namespace buckle::continuation {

class Interrupt {
 public:
  using Clock = std::chrono::steady_clock;
  enum class Reason { None, TimeLimit, Flag };

  /// Never requested.
  Interrupt() = default;
  /// Requested once `seconds` have passed from now (infinite or NaN: never).
  static Interrupt after(double seconds);

  /// Requested from `deadline` on; `seconds` is the limit as the user gave it, counted from now
  /// (for messages: how long the computation ran of it).
  Interrupt &setDeadline(Clock::time_point deadline, double seconds);
  /// Moves the deadline of this Interrupt and of every copy made since setDeadline() to
  /// `seconds` before the one set (never later than an earlier call moved it): room kept for
  /// writing what was computed, which grows with it. No effect without a deadline.
  void keepBeforeDeadline(double seconds) const;
  /// Requested while *flag is true; `what` names the source in messages ("SIGINT received").
  /// The flag must outlive every copy of this Interrupt.
  Interrupt &watch(const std::atomic<bool> *flag, std::string what = "interrupted");

  /// One relaxed atomic load and, with a deadline, one steady-clock read: cheap enough for
  /// every step of every loop.
  Reason reason() const {
    if (flag_ && flag_->load(std::memory_order_relaxed)) return Reason::Flag;
    if (hasDeadline_ && Clock::now() >= deadline_ - Clock::duration(kept_->load(std::memory_order_relaxed)))
      return Reason::TimeLimit;
    return Reason::None;
  }
  bool requested() const { return reason() != Reason::None; }
  /// "time limit of 5 s reached" (with when the computation stopped where that was well before
  /// the limit, the rest kept for writing), the flag's `what`, or "" when not requested.
  std::string describe() const;

  bool hasDeadline() const { return hasDeadline_; }
  /// Seconds left before the deadline (+inf without one, ≤ 0 once passed).
  double secondsLeft() const;

 private:
  bool hasDeadline_ = false;
  Clock::time_point deadline_{};
  Clock::time_point start_{};  ///< when setDeadline() was called: the limit counts from there
  /// keepBeforeDeadline(), in clock ticks, shared by the copies
  std::shared_ptr<std::atomic<Clock::rep>> kept_ = std::make_shared<std::atomic<Clock::rep>>(0);
  double seconds_ = 0.0;
  const std::atomic<bool> *flag_ = nullptr;
  std::string flagWhat_;
};

}  // namespace buckle::continuation
