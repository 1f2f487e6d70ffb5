#include "scene/progress.h"

#include <cstdio>
#include <sstream>

namespace buckle::scene {

namespace {
double seconds(std::chrono::steady_clock::duration d) { return std::chrono::duration<double>(d).count(); }
}  // namespace

Progress::Progress(std::ostream& out, Mode mode, double liveAfter, double lineInterval)
    : out_(out),
      mode_(mode),
      liveAfter_(liveAfter),
      lineInterval_(lineInterval),
      start_(std::chrono::steady_clock::now()),
      last_(start_) {}

Progress::~Progress() { finish(); }

double Progress::elapsed() const { return seconds(std::chrono::steady_clock::now() - start_); }

void Progress::stage(const std::string& name, const std::string& caseLabel, int caseIndex, int caseCount) {
  stage_ = name;
  case_ = caseLabel;
  caseIndex_ = caseIndex;
  caseCount_ = caseCount;
  detail_.clear();
  report();
}

void Progress::step(int branch, int points, double parameter, int specials, int queued) {
  if (mode_ == Mode::Off) return;
  // Cheap exit first: the tracer calls this at every point.
  const auto now = std::chrono::steady_clock::now();
  const double interval = mode_ == Mode::Live ? 0.1 : lineInterval_;
  if (seconds(now - start_) < liveAfter_ || (anyPrinted_ && seconds(now - last_) < interval)) return;
  std::ostringstream os;
  os.precision(6);
  os << "branch " << branch << ", " << points << " points, parameter " << parameter << ", " << specials
     << " special point" << (specials == 1 ? "" : "s");
  if (queued > 0) os << "; " << queued << " branch point" << (queued == 1 ? "" : "s") << " queued";
  detail_ = os.str();
  report();
}

void Progress::note(const std::string& what) {
  detail_ = what;
  report();
}

void Progress::report() {
  if (mode_ == Mode::Off) return;
  const auto now = std::chrono::steady_clock::now();
  const double t = seconds(now - start_);
  // the first report as soon as the run has lasted liveAfter_, then at the mode's interval
  const double interval = mode_ == Mode::Live ? 0.1 : lineInterval_;
  if ((t < liveAfter_ || (anyPrinted_ && seconds(now - last_) < interval))) return;
  last_ = now;
  std::ostringstream os;
  os.precision(3);
  os << "[" << std::fixed << t << " s] ";
  os.unsetf(std::ios::floatfield);
  if (caseCount_ > 1) os << "case " << caseIndex_ + 1 << "/" << caseCount_ << " ";
  if (!case_.empty()) os << "\"" << case_ << "\" ";
  os << stage_;
  if (!detail_.empty()) os << ": " << detail_;
  std::string line = os.str();
  if (mode_ == Mode::Live) {
    if (line.size() > 150) line = line.substr(0, 147) + "...";
    out_ << "\r" << line << "\033[K" << std::flush;  // rewrite in place, clear the rest
    printedLive_ = true;
  } else {
    out_ << "buckle: " << line << "\n" << std::flush;
  }
  anyPrinted_ = true;
}

void Progress::warn(const std::string& what) {
  if (mode_ == Mode::Off) return;
  if (mode_ == Mode::Live && printedLive_) out_ << "\r\033[K";  // the live line goes on below it
  out_ << "buckle: warning: " << what << "\n" << std::flush;
}

void Progress::finish() {
  if (mode_ == Mode::Live && printedLive_) out_ << "\r\033[K" << std::flush;
  printedLive_ = false;
}

}  // namespace buckle::scene
