// SIGINT / SIGTERM during a long run: the first one only sets a flag, which every loop of the
// computation checks through a continuation::Interrupt, so the run stops within a step and
// writes what it computed; the handlers are one-shot (SA_RESETHAND), so a second signal ends the
// program at once the usual way.
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
