#include "scene/signals.h"

#include <csignal>
#include <ctime>
#include <string>

namespace buckle::scene {

namespace {

std::atomic<bool> gReceived{false};
volatile std::sig_atomic_t gSignal = 0;
struct sigaction gPreviousInt, gPreviousTerm, gPreviousHup;

volatile std::sig_atomic_t gFirstSecond = 0;  // CLOCK_MONOTONIC time of the first signal (whole s)
volatile std::sig_atomic_t gFirstMilli = 0;   // ... and its milliseconds

long long nowMilliseconds() {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);  // async-signal-safe (POSIX)
  return static_cast<long long>(t.tv_sec) * 1000 + t.tv_nsec / 1000000;
}

const char* sigabbrev(int sig) {
  return sig == SIGINT ? "SIGINT" : sig == SIGTERM ? "SIGTERM" : sig == SIGHUP ? "SIGHUP" : "signal";
}

// Only async-signal-safe calls here. The first signal sets the flag; a later one ends the
// program the usual way (default action, re-raised). One sent twice at once — timeout(1) sends
// it to the child and to its process group — counts once: a repeat within 200 ms is ignored.
extern "C" void onSignal(int sig) {
  const long long now = nowMilliseconds();
  if (gSignal == 0) {
    gSignal = sig;
    gFirstSecond = static_cast<std::sig_atomic_t>(now / 1000);
    gFirstMilli = static_cast<std::sig_atomic_t>(now % 1000);
    gReceived.store(true, std::memory_order_relaxed);  // lock-free: async-signal-safe
    return;
  }
  const long long first = static_cast<long long>(gFirstSecond) * 1000 + gFirstMilli;
  if (now - first < 200) return;
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

}  // namespace

static_assert(std::atomic<bool>::is_always_lock_free, "the signal flag must be lock-free");

SignalGuard::SignalGuard() {
  gReceived.store(false);
  gSignal = 0;
  gFirstSecond = gFirstMilli = 0;
  struct sigaction action {};
  action.sa_handler = onSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;  // a second signal: default action, from the handler
  sigaction(SIGINT, &action, &gPreviousInt);
  sigaction(SIGTERM, &action, &gPreviousTerm);
  sigaction(SIGHUP, &action, &gPreviousHup);
}

SignalGuard::~SignalGuard() {
  sigaction(SIGINT, &gPreviousInt, nullptr);
  sigaction(SIGTERM, &gPreviousTerm, nullptr);
  sigaction(SIGHUP, &gPreviousHup, nullptr);
}

const std::atomic<bool>* SignalGuard::flag() { return &gReceived; }

int SignalGuard::signal() { return gSignal; }

int SignalGuard::exitCode() { return gSignal ? 128 + gSignal : 0; }

sigset_t stopSignals() {
  sigset_t set;
  sigemptyset(&set);
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&set, sig);
  return set;
}

std::string SignalGuard::description() {
  return gSignal ? "interrupted by a signal (" + std::string(sigabbrev(gSignal)) + ")" : std::string();
}

std::string stopSignalReason() {
  if (gReceived.load(std::memory_order_relaxed)) return SignalGuard::description();
  sigset_t pending;
  if (sigpending(&pending) != 0) return "";
  for (int sig : {SIGINT, SIGTERM, SIGHUP})
    if (sigismember(&pending, sig) == 1) return "interrupted by a signal (" + std::string(sigabbrev(sig)) + ")";
  return "";
}

}  // namespace buckle::scene
