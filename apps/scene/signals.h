// SIGINT / SIGTERM / SIGHUP during a long run: the first one only sets a flag, which every loop of the
// computation checks through a continuation::Interrupt, so the run stops within a step and
// writes what it computed; a second signal (later than 200 ms after the first: the same signal
// delivered twice at once counts once) ends the program the usual way.
#pragma once

#include <atomic>
#include <csignal>
#include <string>

namespace buckle::scene {

/// Installs the handlers for its lifetime and restores the previous ones afterwards.
class SignalGuard {
 public:
  SignalGuard();
  ~SignalGuard();
  SignalGuard(const SignalGuard&) = delete;
  SignalGuard& operator=(const SignalGuard&) = delete;

  /// True once SIGINT, SIGTERM or SIGHUP arrived (set from the handler).
  static const std::atomic<bool>* flag();
  /// The signal received (0: none).
  static int signal();
  /// Conventional exit status after a signal: 128 + its number (130 SIGINT, 143 SIGTERM,
  /// 129 SIGHUP).
  static int exitCode();
  /// "interrupted by a signal (SIGINT)" naming the signal received ("" before one).
  static std::string description();
};

/// The signals a run stops on (SignalGuard) and the output writers hold back while they write
/// (output.h, StagingDirectory).
sigset_t stopSignals();

/// Why the writers must stop now: a stop signal received (SignalGuard) or held back, pending,
/// while they write; "" otherwise.
std::string stopSignalReason();

}  // namespace buckle::scene
