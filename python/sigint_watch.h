// Ctrl-C while the module computes without the GIL. Python's own SIGINT handler only sets a flag
// that the interpreter looks at between bytecodes, and none run during a long C++ computation;
// so for its duration a C handler sets an atomic flag that the computation's
// continuation::Interrupt watches (it stops within a step and keeps what it computed), and
// afterwards KeyboardInterrupt is raised as Python would have.
#pragma once

#include <pybind11/pybind11.h>

#include <atomic>
#include <csignal>

namespace buckle::python {

class SigintWatch {
 public:
  /// Installs the handler when called from the main thread and Python's SIGINT handler is its
  /// default one (which raises KeyboardInterrupt); otherwise watches nothing.
  SigintWatch();
  /// Restores the previous handler.
  ~SigintWatch();
  SigintWatch(const SigintWatch&) = delete;
  SigintWatch& operator=(const SigintWatch&) = delete;

  /// The flag for continuation::Interrupt::watch (one that is never set when nothing is watched,
  /// so a computation in another thread is not stopped by the main thread's Ctrl-C).
  const std::atomic<bool>* flag() const;
  /// True when SIGINT arrived while watched.
  bool interrupted() const;
  /// Raises KeyboardInterrupt (pybind11::error_already_set) when SIGINT arrived. Needs the GIL.
  void raiseIfInterrupted() const;

 private:
  bool installed_ = false;
  std::atomic<bool> never_{false};  // what a watch that installed nothing hands out
  struct sigaction previous_ {};
};

}  // namespace buckle::python
