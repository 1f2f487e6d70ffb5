#include "scene/atlas.h"
#include "buckle/continuation/available_cores.h"

#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "buckle/continuation/byte_packing.h"
#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/post_buckling.h"
#include "scene/child_process.h"
#include "scene/columns.h"
#include "scene/output.h"
#include "scene/signals.h"

namespace buckle::scene {

namespace mech = buckle::mechanics;
namespace fs = std::filesystem;

namespace {

void checkAxis(const AtlasAxis& a, const std::string& opt) {
  if (a.name != "a" && a.name != "L0" && a.name != "n")
    throw std::invalid_argument(opt + " must be one of a, L0, n (got \"" + a.name + "\")");
  if (!std::isfinite(a.from) || !std::isfinite(a.to))
    throw std::invalid_argument(opt + " range must be finite");
  if (a.count < 1 || a.count > 1000) throw std::invalid_argument(opt + " count must be in [1, 1000]");
  const double lo = std::min(a.from, a.to);
  if (a.name == "a" && lo < 0.0) throw std::invalid_argument(opt + ": a/b must be >= 0");
  if (a.name == "L0" && !(lo > 0.0)) throw std::invalid_argument(opt + ": L0/b must be > 0");
  if (a.name == "n" && (lo < 1.0 || std::max(a.from, a.to) > 200.0))
    throw std::invalid_argument(opt + ": n must be in [1, 200]");
}

void computeCell(AtlasCell& c) {
  const mech::SegmentParameters p = mech::SegmentParameters::symmetric(c.a, 1.0, 1.0, c.L0);
  try {
    const mech::FirstBuckling fb =
        mech::firstBuckling(mech::Chain::uniform(c.n, p), mech::EndCondition::clampedPinned(0.0, 0.0),
                            Eigen::Vector3d(1.0, 0.0, 0.0), Eigen::VectorXd::Zero(c.n));
    c.straightStable = fb.startStable;
    c.firstCritical = fb.critical;
    c.firstShape = fb.shape;
    c.postBuckling = mech::toString(fb.kind);
    c.postSlope = fb.slope;
    c.error = fb.message;
  } catch (const std::exception& e) {  // an invalid segment (e.g. a/b too large) names itself
    c.firstCritical = kNaN;
    c.postBuckling = "failed";
    c.error = e.what();
  }
}

int postCode(const std::string& s) {
  if (s == "supercritical") return 2;
  if (s == "subcritical") return 1;
  if (s == "unstable start") return 0;
  if (s == "none") return 3;
  return -1;
}

std::string axisLabel(const std::string& name) {
  if (name == "a") return "a/b";
  if (name == "L0") return "L^0/b";
  return "n (segments)";
}

std::string num(double v) {
  if (!std::isfinite(v)) return "nan";
  std::ostringstream os;
  os.precision(12);
  os << v;
  return os.str();
}

}  // namespace

void validateAtlas(const AtlasOptions& o) {
  checkAxis(o.x, "--x");
  checkAxis(o.y, "--y");
  if (o.x.name == o.y.name) throw std::invalid_argument("--x and --y must be different parameters");
  if (!(o.a >= 0.0) || !std::isfinite(o.a)) throw std::invalid_argument("--a must be a finite number >= 0");
  if (!(o.L0 > 0.0) || !std::isfinite(o.L0)) throw std::invalid_argument("--L0 must be a finite number > 0");
  if (o.n < 1 || o.n > 200) throw std::invalid_argument("--segments must be in [1, 200]");
  if (o.threads < 0) throw std::invalid_argument("--threads must be >= 0");
}

std::vector<AtlasCell> atlasGrid(const AtlasOptions& o) {
  validateAtlas(o);
  std::vector<AtlasCell> cells(size_t(o.x.count) * size_t(o.y.count));
  for (int j = 0; j < o.y.count; ++j)
    for (int i = 0; i < o.x.count; ++i) {
      AtlasCell& c = cells[size_t(j) * size_t(o.x.count) + size_t(i)];
      c.x = o.x.value(i);
      c.y = o.y.value(j);
      c.a = o.a;
      c.L0 = o.L0;
      c.n = o.n;
      for (const auto& [axis, v] : {std::pair{&o.x, c.x}, std::pair{&o.y, c.y}}) {
        if (axis->name == "a") c.a = v;
        if (axis->name == "L0") c.L0 = v;
        if (axis->name == "n") c.n = static_cast<int>(std::lround(v));
      }
      c.kappa = c.L0 - 2.0 * (1.0 - c.a * c.a);
      c.firstCritical = kNaN;
      c.postBuckling = "not computed";
    }
  return cells;
}

size_t computeCells(std::vector<AtlasCell>& cells, const AtlasShare& share, int threadCount,
                    const continuation::Interrupt& interrupt, const std::function<void(int, int)>& progress) {
  if (share.parts < 1 || share.part < 0 || share.part >= share.parts)
    throw std::invalid_argument("atlas share " + std::to_string(share.part) + " of " + std::to_string(share.parts));
  std::vector<size_t> mine;
  mine.reserve(share.size(cells.size()));
  for (size_t k = 0; k < cells.size(); ++k)
    if (share.owns(k)) mine.push_back(k);
  const int total = static_cast<int>(mine.size());
  unsigned threads = threadCount > 0 ? unsigned(threadCount) : unsigned(continuation::availableCores());
  threads = std::min<unsigned>(threads, unsigned(std::max(total, 1)));
  std::atomic<int> next{0}, done{0};
  std::mutex progressMutex;
  auto worker = [&]() {
    for (int k = next++; k < total; k = next++) {
      if (interrupt.requested()) {
        next = total;  // the other workers stop at their next cell too
        break;
      }
      computeCell(cells[mine[size_t(k)]]);
      const int d = ++done;
      if (progress) {
        std::lock_guard<std::mutex> lock(progressMutex);
        progress(d, total);
      }
    }
  };
  std::vector<std::thread> pool;
  for (unsigned t = 0; t < threads; ++t) pool.emplace_back(worker);
  for (std::thread& t : pool) t.join();
  if (done < total) {
    const std::string why = "stopped early: " + interrupt.describe();
    for (size_t k : mine)
      if (cells[k].postBuckling == "not computed") cells[k].error = why;
  }
  return size_t(done.load());
}

std::vector<AtlasCell> computeAtlas(const AtlasOptions& o, const std::function<void(int, int)>& progress) {
  std::vector<AtlasCell> cells = atlasGrid(o);
  computeCells(cells, AtlasShare{}, o.threads, continuation::Interrupt{}, progress);
  return cells;
}

std::string packAtlasCells(const std::vector<AtlasCell>& cells, const AtlasShare& share) {
  continuation::ByteWriter out;
  for (size_t k = 0; k < cells.size(); ++k) {
    if (!share.owns(k)) continue;
    const AtlasCell& c = cells[k];
    out.put(std::uint64_t(k));
    out.put(std::uint8_t(c.straightStable ? 1 : 0));
    out.put(c.firstCritical);
    out.put(c.postSlope);
    out.putString(c.firstShape);
    out.putString(c.postBuckling);
    out.putString(c.error);
  }
  return out.release();
}

void unpackAtlasCells(const std::string& bytes, std::vector<AtlasCell>& cells) {
  continuation::ByteReader in(bytes, "atlas cells");
  while (!in.done()) {
    const auto k = in.get<std::uint64_t>();
    if (k >= cells.size())
      in.fail("cell " + std::to_string(k) + " is outside the grid of " + std::to_string(cells.size()));
    AtlasCell& c = cells[size_t(k)];
    c.straightStable = in.get<std::uint8_t>() != 0;
    c.firstCritical = in.get<double>();
    c.postSlope = in.get<double>();
    c.firstShape = in.getString();
    c.postBuckling = in.getString();
    c.error = in.getString();
  }
}

std::vector<std::string> writeAtlas(const AtlasOptions& o, const std::vector<AtlasCell>& cells,
                                    const std::string& dirName, std::string& gnuplotNote) {
  const fs::path dir(dirName);
  {
    // The two axes are two of a, L0, n (summary.json says which): each column appears once.
    std::ofstream csv(dir / "atlas.csv");
    csv << "a,L0,n,kappa,straight_stable,first_critical_Fx,first_shape,post_buckling,post_slope,error\n";
    for (const AtlasCell& c : cells) {
      std::string error;  // CSV quoting: a quote inside a quoted field is doubled
      for (char ch : c.error) error += ch == '"' ? std::string("\"\"") : std::string(1, ch);
      csv << num(c.a) << "," << num(c.L0) << "," << c.n << "," << num(c.kappa) << "," << (c.straightStable ? 1 : 0)
          << "," << num(c.firstCritical) << "," << c.firstShape << "," << c.postBuckling << "," << num(c.postSlope)
          << ",\"" << error << "\"\n";
    }
    if (!csv) throw std::runtime_error("cannot write " + (dir / "atlas.csv").string());
  }
  const fs::path plots = dir / "plots";
  fs::create_directories(plots);
  {
    std::ofstream dat(plots / "atlas.dat");
    for (int j = 0; j < o.y.count; ++j) {
      for (int i = 0; i < o.x.count; ++i) {
        const AtlasCell& c = cells[size_t(j) * size_t(o.x.count) + size_t(i)];
        dat << num(c.x) << " " << num(c.y) << " " << (c.straightStable ? num(c.firstCritical) : "NaN") << " "
            << (c.postBuckling == "not computed" ? "NaN" : std::to_string(postCode(c.postBuckling))) << "\n";
      }
      dat << "\n";
    }
  }
  const double dx = o.x.count > 1 ? std::abs(o.x.to - o.x.from) / (o.x.count - 1) : 1.0;
  const double dy = o.y.count > 1 ? std::abs(o.y.to - o.y.from) / (o.y.count - 1) : 1.0;
  std::ostringstream range;
  range << "set xrange [" << num(std::min(o.x.from, o.x.to) - dx / 2) << ":" << num(std::max(o.x.from, o.x.to) + dx / 2)
        << "]\nset yrange [" << num(std::min(o.y.from, o.y.to) - dy / 2) << ":"
        << num(std::max(o.y.from, o.y.to) + dy / 2) << "]\n";
  std::string others;
  for (const char* name : {"a", "L0", "n"})
    if (o.x.name != name && o.y.name != name)
      others = std::string(name) == "a" ? "a/b = " + num(o.a) : std::string(name) == "L0" ? "L^0/b = " + num(o.L0)
                                                                                            : "n = " + std::to_string(o.n);
  const std::string common = "set xlabel '" + axisLabel(o.x.name) + "'\nset ylabel '" + axisLabel(o.y.name) + "'\n" +
                             range.str() + "set tics out\n";
  {
    std::ofstream gp(plots / "atlas_critical_body.gp");
    gp << common << "set title 'First critical force F_x of the straight clamped-pinned chain (" << others
       << ", b = k = 1); white: straight start unstable'\n"
       << "set cblabel 'F_x (units of k b)'\nset palette rgbformulae 33,13,10\n"
       << "plot 'atlas.dat' using 1:2:3 with image notitle\n";
  }
  {
    std::ofstream gp(plots / "atlas_post_buckling_body.gp");
    gp << common << "set title 'Post-buckling branch (" << others << ", b = k = 1)'\n"
       << "set palette defined (-1.5 'black', -0.5 'black', -0.5 '#bbbbbb', 0.5 '#bbbbbb', 0.5 '#d62728', "
          "1.5 '#d62728', 1.5 '#2ca02c', 2.5 '#2ca02c', 2.5 '#1f77b4', 3.5 '#1f77b4')\nset cbrange [-1.5:3.5]\n"
       << "set rmargin 22\n"
       << "set cbtics ('failed' -1, 'unstable start' 0, 'subcritical' 1, 'supercritical' 2, 'no critical load' 3)\n"
       << "plot 'atlas.dat' using 1:2:4 with image notitle\n";
  }
  const std::string gnuplot = findGnuplot();
  std::vector<std::string> files;
  gnuplotNote = gnuplot.empty() ? "not found: gnuplot is not installed (Debian: gnuplot-nox); data and scripts in plots/"
                                : gnuplot;
  for (const char* name : {"atlas_critical", "atlas_post_buckling"}) {
    std::ofstream gp(plots / (std::string(name) + ".gp"));
    gp << "set terminal pngcairo size 1000,760 enhanced font 'DejaVu Sans,11'\nset output '" << name << ".png'\nload '"
       << name << "_body.gp'\nset output\nreset\nset terminal svg size 1000,760 enhanced font 'DejaVu Sans,11' "
       << "background 'white'\nset output '" << name << ".svg'\nload '" << name << "_body.gp'\nset output\n";
    gp.close();
    if (gnuplot.empty()) continue;
    // no shell: an output path with quotes in it stays a path (child_process.h)
    const ChildOutcome drawn =
        runChild(gnuplot, {std::string(name) + ".gp"}, plots.string(), std::string(name) + ".log", stopSignalReason);
    if (drawn.exitedZero && fs::exists(plots / (std::string(name) + ".png"))) {
      files.push_back(std::string("plots/") + name + ".png");
      files.push_back(std::string("plots/") + name + ".svg");
      std::error_code ec;
      fs::remove(plots / (std::string(name) + ".log"), ec);
    }
  }
  return files;
}

}  // namespace buckle::scene
