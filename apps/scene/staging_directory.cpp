// The staging directory of a run's outputs (output.h): created beside the target with the stop
// signals held back, renamed onto the target only when every file is written, removed otherwise.
#include <pthread.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <random>
#include <stdexcept>
#include <string>

#include "scene/output.h"
#include "scene/signals.h"

namespace buckle::scene {

namespace fs = std::filesystem;

StagingDirectory::StagingDirectory(const std::string& target) : target_(target) {
  fs::path t = fs::absolute(fs::path(target)).lexically_normal();
  if (t.filename().empty()) t = t.parent_path();
  target_ = t.string();
  fs::create_directories(t.parent_path());
  const sigset_t hold = stopSignals();
  pthread_sigmask(SIG_BLOCK, &hold, &previousMask_);
  // Not mkdtemp: it makes the directory 0700, and the renamed output would not follow the
  // umask. mkdir(0777) does; the random suffix and EEXIST retry give the same uniqueness.
  std::random_device seed;
  std::mt19937_64 random(seed() ^ (std::uint64_t(::getpid()) << 32));
  const char* const alphabet = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789";
  for (int attempt = 0; attempt < 100; ++attempt) {
    std::string suffix(6, 'x');
    for (char& ch : suffix) ch = alphabet[random() % 62];
    const std::string candidate = (t.parent_path() / ("." + t.filename().string() + ".tmp-" + suffix)).string();
    if (::mkdir(candidate.c_str(), 0777) == 0) {
      path_ = candidate;
      return;
    }
    if (errno != EEXIST) break;
  }
  const int error = errno;
  pthread_sigmask(SIG_SETMASK, &previousMask_, nullptr);
  throw std::runtime_error("cannot create a temporary directory next to " + target_ + ": " + std::strerror(error));
}

StagingDirectory::~StagingDirectory() {
  if (!committed_) {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  pthread_sigmask(SIG_SETMASK, &previousMask_, nullptr);  // a held-back signal is delivered now
}

void StagingDirectory::commit() {
  std::error_code ec;
  std::string old;
  if (fs::exists(target_)) {
    old = path_ + ".old";
    fs::rename(target_, old, ec);
    if (ec) throw std::runtime_error("cannot move the previous " + target_ + " aside: " + ec.message());
  }
  fs::rename(path_, target_, ec);
  if (ec) {
    if (!old.empty()) fs::rename(old, target_, ec);
    throw std::runtime_error("cannot rename " + path_ + " to " + target_ + ": " + ec.message());
  }
  committed_ = true;
  if (!old.empty()) fs::remove_all(old, ec);
}

}  // namespace buckle::scene
