#include "scene/child_process.h"

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <fcntl.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

namespace buckle::scene {

namespace {

using Clock = std::chrono::steady_clock;

/// Waits for `pid`; with `deadline`, at most until then. True when it ended (status in `status`).
bool reap(pid_t pid, int& status, bool bounded, Clock::time_point deadline) {
  for (;;) {
    const pid_t r = ::waitpid(pid, &status, WNOHANG);
    if (r == pid) return true;
    if (r < 0 && errno != EINTR) return true;  // not our child any more: nothing to wait for
    if (bounded && Clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

}  // namespace

ChildOutcome runChild(const std::string& program, const std::vector<std::string>& arguments, const std::string& dir,
                      const std::string& log, const std::function<std::string()>& stop) {
  ChildOutcome outcome;
  // everything the child needs is prepared before fork: after it, only async-signal-safe calls
  std::vector<std::string> words{program};
  words.insert(words.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  sigset_t none;
  sigemptyset(&none);

  const pid_t pid = ::fork();
  if (pid < 0) {
    outcome.error = std::string("cannot start ") + program + ": " + std::strerror(errno);
    return outcome;
  }
  if (pid == 0) {
    ::sigprocmask(SIG_SETMASK, &none, nullptr);  // the writers' held-back signals are not the child's
    if (::chdir(dir.c_str()) != 0) ::_exit(126);
    const int in = ::open("/dev/null", O_RDONLY);
    const int out = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0666);
    if (in < 0 || out < 0 || ::dup2(in, 0) < 0 || ::dup2(out, 1) < 0 || ::dup2(out, 2) < 0) ::_exit(126);
    ::execv(program.c_str(), argv.data());
    ::_exit(127);
  }
  int status = 0;
  for (;;) {
    if (reap(pid, status, true, Clock::now() + std::chrono::milliseconds(20))) break;
    outcome.stopped = stop ? stop() : std::string();
    if (outcome.stopped.empty()) continue;
    ::kill(pid, SIGTERM);
    if (!reap(pid, status, true, Clock::now() + std::chrono::milliseconds(500))) {
      ::kill(pid, SIGKILL);
      reap(pid, status, false, Clock::now());
    }
    return outcome;
  }
  outcome.exitedZero = WIFEXITED(status) && WEXITSTATUS(status) == 0;
  if (WIFEXITED(status) && WEXITSTATUS(status) == 127) outcome.error = "cannot run " + program;
  return outcome;
}

}  // namespace buckle::scene
