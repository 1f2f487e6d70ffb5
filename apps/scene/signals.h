// SIGINT / SIGTERM during a long run: the first one only sets a flag, which every loop of the
// computation checks through a continuation::Interrupt, so the run stops within a step and
// writes what it computed; a second signal (later than 200 ms after the first: the same signal
// delivered twice at once counts once) ends the program the usual way.
#pragma once

#include <atomic>

namespace buckle::scene {

/// Installs the handlers for its lifetime and restores the previous ones afterwards.
class SignalGuard {
 public:
  SignalGuard();
  ~SignalGuard();
  SignalGuard(const SignalGuard&) = delete;
  SignalGuard& operator=(const SignalGuard&) = delete;

  /// True once SIGINT or SIGTERM arrived (set from the handler).
  static const std::atomic<bool>* flag();
  /// The signal received (0: none).
  static int signal();
  /// Conventional exit status after a signal: 128 + its number (130 SIGINT, 143 SIGTERM).
  static int exitCode();
};

}  // namespace buckle::scene
