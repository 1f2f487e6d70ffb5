#include "scene/signals.h"

#include <csignal>

namespace buckle::scene {

namespace {

std::atomic<bool> gReceived{false};
volatile std::sig_atomic_t gSignal = 0;
struct sigaction gPreviousInt, gPreviousTerm;

extern "C" void onSignal(int sig) {
  gSignal = sig;
  gReceived.store(true, std::memory_order_relaxed);  // lock-free: async-signal-safe
}

}  // namespace

static_assert(std::atomic<bool>::is_always_lock_free, "the signal flag must be lock-free");

SignalGuard::SignalGuard() {
  gReceived.store(false);
  gSignal = 0;
  struct sigaction action {};
  action.sa_handler = onSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND;  // a second signal: default action (the program ends)
  sigaction(SIGINT, &action, &gPreviousInt);
  sigaction(SIGTERM, &action, &gPreviousTerm);
}

SignalGuard::~SignalGuard() {
  sigaction(SIGINT, &gPreviousInt, nullptr);
  sigaction(SIGTERM, &gPreviousTerm, nullptr);
}

const std::atomic<bool>* SignalGuard::flag() { return &gReceived; }

int SignalGuard::signal() { return gSignal; }

int SignalGuard::exitCode() { return gSignal ? 128 + gSignal : 0; }

}  // namespace buckle::scene
