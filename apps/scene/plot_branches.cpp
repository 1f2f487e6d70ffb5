// Bifurcation and stiffness diagrams (columns of branches.csv against the path parameter or each
// other): branches by stability, special points marked and labelled apart, summary mode for
// long chains and large trees.
#include "scene/plot_internal.h"

#include <set>

#include "scene/special_marks.h"

namespace buckle::scene::plot_detail {

namespace {

// ---- bifurcation / stiffness (columns of branches.csv) ----------------------------------------

/// Column value at a special point; the columns that exist only at traced points (stiffness,
/// smallest eigenvalue) are interpolated along the special point's branch between the two
/// neighbouring points it lies between (exact where it is a traced point: a joint limit), unless
/// the special point carries its own stiffness (KMIN, located between traced points).
double specialValue(const std::string& column, const mechanics::SpecialPointReport& r, const CaseResult& cr) {
  const double v = columnValue(column, r, cr);
  if (std::isfinite(v) || r.q.size() == 0) return v;
  double best = std::numeric_limits<double>::infinity(), value = v;
  for (size_t i = 0; i + 1 < cr.points.size(); ++i) {
    const mechanics::PointReport &a = cr.points[i], &b = cr.points[i + 1];
    if (a.branch != r.branch || b.branch != r.branch || a.q.size() != r.q.size() || b.q.size() != r.q.size()) continue;
    const Eigen::VectorXd d = b.q - a.q;
    const double len2 = d.squaredNorm();
    double t = len2 > 0 ? std::clamp((r.q - a.q).dot(d) / len2, 0.0, 1.0) : 0.0;
    if (!(len2 > 0)) {
      // a branch whose shape does not change (the straight chain): between these two points in
      // the path parameter, or not at all
      const double dl = b.parameter - a.parameter;
      if (!(dl != 0.0)) continue;
      t = (r.parameter - a.parameter) / dl;
      if (t < 0.0 || t > 1.0) continue;
    }
    const double dist = (r.q - a.q - t * d).norm();
    // off the chord by more than half the spacing: not between these two points
    if (dist > 0.5 * std::sqrt(len2) && dist > 0.0) continue;
    if (dist < best) {
      best = dist;
      value = (1 - t) * columnValue(column, a, cr) + t * columnValue(column, b, cr);
    }
  }
  return value;
}

/// The gnuplot point size of a full-size special-point marker and its half-width in pixels
/// (pngcairo at the plots' size: about 4 px a unit of point size).
constexpr double kMarkerSize = 1.4, kMarkerPixels = 5.6;

/// Indices of the points kept when points closer than `radius` are drawn once: greedy in the
/// given order over a hash grid of cell `radius` (O(points log points)).
std::vector<size_t> thinned(const std::vector<Eigen::Vector2d>& px, double radius) {
  std::vector<size_t> kept;
  std::map<std::pair<long, long>, std::vector<size_t>> grid;  // cell -> kept points in it
  for (size_t i = 0; i < px.size(); ++i) {
    if (!px[i].allFinite()) continue;
    const long cx = long(std::floor(px[i].x() / radius)), cy = long(std::floor(px[i].y() / radius));
    bool near = false;
    for (long dx = -1; dx <= 1 && !near; ++dx)
      for (long dy = -1; dy <= 1 && !near; ++dy) {
        const auto it = grid.find({cx + dx, cy + dy});
        if (it == grid.end()) continue;
        for (size_t k : it->second) near = near || (px[k] - px[i]).norm() < radius;
      }
    if (near) continue;
    grid[{cx, cy}].push_back(i);
    kept.push_back(i);
  }
  return kept;
}

/// Line width and transparency of the branches (gnuplot's `#AARRGGBB`, AA = 0 opaque) such that
/// hundreds of overlapping branches stay apart: full width up to a dozen branches, then thinner
/// and translucent, unstable parts fainter than stable ones.
struct BranchLook {
  double width = 2.0;
  int alphaStable = 0, alphaUnstable = 0;
};
BranchLook branchLook(size_t branches) {
  BranchLook look;
  if (branches <= 12) return look;
  look.width = std::max(0.8, 2.0 * std::sqrt(12.0 / double(branches)));
  look.alphaStable = int(std::min<size_t>(0x50, 0x10 + branches / 4));
  look.alphaUnstable = std::min(0xA0, look.alphaStable + 0x50);
  return look;
}

std::string withAlpha(const std::string& rgb, int alpha) {
  if (alpha <= 0 || rgb.size() != 7 || rgb[0] != '#') return rgb;
  char buf[8];
  std::snprintf(buf, sizeof buf, "%02X", alpha & 0xFF);
  return "#" + std::string(buf) + rgb.substr(1);
}

/// The colour of the branches traced from equilibria the continuation's tree does not reach.
const std::string kDisconnectedColor = "#c51b7d";

/// A bifurcation or stiffness diagram of a run's branches, built in stages that share its data:
/// the branch series, the special points' marks and jumps, the frame, the layout of labels and
/// markers (label_layout.h), then the data files and the gnuplot script.
class BranchPlot {
 public:
  BranchPlot(const Scene& scene, const RunResult& run, const PlotSpec& spec)
      : scene(scene), run(run), spec(spec), cases(selected(spec)), multiCase(cases.size() > 1), ny(spec.y.size()),
        stem(spec.name) {}

  void draw(const fs::path& dir, Script& s) {
    collectSeries();
    collectMarks();
    collectJumps();
    frame(s);
    layout();
    writeData(dir);
    writeScript(s);
  }

 private:
  struct Series {
    int block;
    size_t ordinal, yIdx;  ///< position of the case in the plot's list, column
    bool stable;
    bool any = false;      ///< has a drawable point
    bool disconnected = false;  ///< the branches traced from equilibria the tree does not reach
  };
  // special points: one block per case and type; points of one case at the same place share a
  // label ("BP, JUMP")
  struct Mark {
    size_t ordinal;
    const SpecialStyle* type;  ///< the marker of the point's type
    double x, y;
    std::string label;
    Importance rank;
  };
  struct SpecialBlock {
    int block;
    size_t ordinal;
    const SpecialStyle* type;
    bool small;  ///< a summary's unlabelled markers
  };

  std::string seriesColor(size_t ordinal, size_t j) const { return color(multiCase ? ordinal * ny + j : j); }
  void extend(double x, double y) {
    if (!std::isfinite(x) || !std::isfinite(y)) return;
    xlo = std::min(xlo, x), xhi = std::max(xhi, x), ylo = std::min(ylo, y), yhi = std::max(yhi, y);
    if (spec.type == PlotType::Stiffness) ys.push_back(y);
  }

  /// The branches of every case and column as polylines by stability (and disconnected or not).
  void collectSeries() {
    for (size_t o = 0; o < cases.size(); ++o) {
      const CaseResult& cr = run.cases[cases[o]];
      // disconnected branches (equilibria "branches") are series of their own, in their own colour
      std::set<int> disconnected;
      for (const BranchRecord& b : cr.branches)
        if (b.fromEquilibrium > 0) disconnected.insert(b.id);
      const std::vector<bool> kinds = disconnected.empty() ? std::vector<bool>{false} : std::vector<bool>{false, true};
      for (size_t j = 0; j < ny; ++j) {
        for (const bool disc : kinds)
        for (bool stable : {true, false}) {
          Series se{data.begin(), o, j, stable};
          se.disconnected = disc;
          auto wanted = [&](const mechanics::PointReport& p) { return p.stable == stable && (disconnected.count(p.branch) > 0) == disc; };
          // polylines of consecutive points with the wanted stability; a run keeps the first point
          // of the next run so that stable and unstable parts join
          polylines.emplace_back();
          auto add = [&](double x, double y) {
            data.point({x, y});
            polylines.back().emplace_back(x, y);
            extend(x, y);
            se.any = true;
          };
          for (size_t i = 0; i < cr.points.size(); ++i) {
            const mechanics::PointReport& p = cr.points[i];
            const bool sameBranchNext = i + 1 < cr.points.size() && cr.points[i + 1].branch == p.branch;
            const double x = columnValue(spec.x, p, cr), y = columnValue(spec.y[j], p, cr);
            if (wanted(p) && std::isfinite(x) && std::isfinite(y)) {
              add(x, y);
              if (sameBranchNext && cr.points[i + 1].stable != stable) {
                const mechanics::PointReport& q = cr.points[i + 1];
                add(columnValue(spec.x, q, cr), columnValue(spec.y[j], q, cr));
              }
            }
            if (!wanted(p) || !sameBranchNext || !std::isfinite(x) || !std::isfinite(y)) {
              data.breakLine();
              polylines.emplace_back();
            }
          }
          series.push_back(se);
        }
      }
    }
  }

  /// The special points as marks, and which of them are labelled.
  void collectMarks() {
    size_t branches = 0;  // branches drawn, over the plot's cases
    size_t markers = 0;  // one per special point and column
    for (size_t c : cases) markers += run.cases[c].specials.size() * ny;
    summary =
        spec.labels == PlotLabels::Summary || (spec.labels == PlotLabels::Auto && markers > kSummaryAboveMarkers);
    for (size_t o = 0; o < cases.size(); ++o) {
      const CaseResult& cr = run.cases[cases[o]];
      const std::vector<Importance> rank = importance(cr);
      for (size_t i = 0; i < cr.specials.size(); ++i) {
        const SpecialPointResult& r = cr.specials[i];
        const SpecialStyle* type = &specialStyle(r.type);
        ++records[type];
        for (size_t j = 0; j < ny; ++j) {
          const double x = specialValue(spec.x, r, cr), y = specialValue(spec.y[j], r, cr);
          if (!std::isfinite(x) || !std::isfinite(y)) continue;
          marks.push_back({o, type, x, y, specialLabel(r, summary), rank[i]});
          extend(x, y);
        }
      }
      std::vector<int> ids;
      for (const mechanics::PointReport& p : cr.points)
        if (ids.empty() || ids.back() != p.branch) ids.push_back(p.branch);
      std::sort(ids.begin(), ids.end());
      branches += size_t(std::unique(ids.begin(), ids.end()) - ids.begin());
    }
    look = branchLook(branches);
    // the marks labelled: all of them, or in a summary the primary branch's branch points and then,
    // up to a budget, the jumps and first folds (in the order the branches were traced)
    labelled.assign(marks.size(), !summary);
    if (summary) {
      std::vector<size_t> order;
      for (size_t i = 0; i < marks.size(); ++i)
        if (marks[i].rank != Importance::Other) order.push_back(i);
      std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return marks[a].rank < marks[b].rank; });
      size_t extra = 0;
      for (size_t i : order)
        if (marks[i].rank == Importance::PrimaryBranchPoint || extra++ < kSummaryExtraLabels) labelled[i] = true;
    }
  }

  /// The jumps: arrows from the fold to the landing point.
  void collectJumps() {
    for (size_t c : cases) {
      const CaseResult& cr = run.cases[c];
      for (const SpecialPointResult& r : cr.specials) {
        if (!r.landing.success || r.landing.q.size() == 0) continue;
        mechanics::SpecialPointReport to = r;
        to.q = r.landing.q;
        to.F = r.landing.F;
        to.pose = r.landing.pose;
        for (size_t j = 0; j < ny; ++j) {
          const double x0 = columnValue(spec.x, r, cr), y0 = columnValue(spec.y[j], r, cr);
          const double x1 = columnValue(spec.x, to, cr), y1 = columnValue(spec.y[j], to, cr);
          if (!std::isfinite(x0) || !std::isfinite(y0) || !std::isfinite(x1) || !std::isfinite(y1)) continue;
          arrows.push_back({{x0, y0}, {x1, y1}});
          extend(x0, y0);
          extend(x1, y1);
          anyJump = true;
        }
      }
    }
  }

  /// The frame: ranges from the data, margins fixed, the key in the right margin.
  void frame(const Script& s) {
    f.width = s.width;
    f.height = s.height;
    for (const SpecialStyle& st : specialStyles())
      for (const Mark& m : marks)
        if (m.type == &st) {
          typesPresent.push_back(&st);
          break;
        }
    // the key's width: gnuplot sizes it with the main font's advance (11 pt: about 8.2 px per
    // character) over the longest title plus the sample
    size_t keyChars = summary ? 22 : 8;  // a summary's key title: lines of up to 22 characters
    // a summary's key gives the count of each type: " (2479)"
    for (const SpecialStyle* type : typesPresent)
      keyChars = std::max(keyChars, glyphs(type->key) + (summary ? 3 + std::to_string(records[type]).size() : 0));
    if (multiCase || ny > 1)
      for (size_t o = 0; o < cases.size(); ++o)
        for (size_t j = 0; j < ny; ++j)
          keyChars = std::max(keyChars, glyphs(run.cases[cases[o]].label) + (ny > 1 ? 1 + spec.y[j].size() : 0));
    f.right = std::clamp(1.0 - (8.2 * double(keyChars + 6) + 30.0) / f.width, 0.5, 0.8);
    std::tie(f.xlo, f.xhi) = framedNiceRange(xlo, xhi);
    // stiffness spans decades (the straight chain against a buckled one): a log axis in whole decades
    // when every drawn value is positive and they span more than two
    if (spec.type == PlotType::Stiffness && ylo <= 0.0) std::tie(ylo, yhi) = framedRange(ys);
    f.logY = spec.type == PlotType::Stiffness && ylo > 0.0 && std::isfinite(yhi) && yhi > 100.0 * ylo;
    // both signs over decades (a stiffness through a pole, or negative past a branch point): a
    // symmetric-log axis, linear within the smaller magnitudes' decade
    f.symlog = spec.type == PlotType::Stiffness && !f.logY ? symlogThreshold(ys, ylo, yhi) : 0.0;
    if (f.logY) {
      f.ylo = std::floor(std::log10(ylo)), f.yhi = std::ceil(std::log10(yhi));
    } else if (f.symlog > 0.0) {
      const double lo = f.transformY(ylo), hi = f.transformY(yhi);
      f.ylo = lo - kFrameMargin * (hi - lo);
      f.yhi = hi + kFrameMargin * (hi - lo);
    } else
      std::tie(f.ylo, f.yhi) = framedNiceRange(ylo, yhi);
  }

  /// Where the curves, jumps and unlabelled markers lie, then the labels placed around them.
  void layout() {
    occupied = Occupancy(f.width, f.height);
    for (const auto& line : polylines)
      for (size_t i = 0; i + 1 < line.size(); ++i)
        occupied.segment(f.pixel(line[i].x(), line[i].y()), f.pixel(line[i + 1].x(), line[i + 1].y()));
    // jumps: block 0 the arrows (x y dx dy: the whole jump, or a hop's last piece with the head),
    // block 1 the hops' bodies (label_layout.h, jumpPath: at least kJumpMinPixels long on screen)
    occupied.finish();
    jumps.begin();
    std::vector<std::vector<Eigen::Vector2d>> jumpPaths;
    for (const auto& [a, b] : arrows) {
      jumpPaths.push_back(jumpPath(f.pixel(a.x(), a.y()), f.pixel(b.x(), b.y()), kJumpMinPixels, occupied));
      const std::vector<Eigen::Vector2d>& path = jumpPaths.back();
      for (size_t k = 0; k + 1 < path.size(); ++k) occupied.segment(path[k], path[k + 1]);
    }
    for (const std::vector<Eigen::Vector2d>& path : jumpPaths) {
      const Eigen::Vector2d p = f.data(path[path.size() - 2]), q = f.data(path.back());
      jumps.point({p.x(), p.y(), q.x() - p.x(), q.y() - p.y()});
    }
    jumps.begin();
    for (const std::vector<Eigen::Vector2d>& path : jumpPaths) {
      if (path.size() <= 2) continue;
      for (size_t k = 0; k + 1 < path.size(); ++k) {
        const Eigen::Vector2d d = f.data(path[k]);
        jumps.point({d.x(), d.y()});
      }
      jumps.breakLine();
    }
    // a summary's unlabelled markers, per case and type, those closer than kThinPixels drawn once;
    // a label may cover them only where it must (like a curve)
    drawn.assign(marks.size(), true);
    if (summary) {
      for (size_t o = 0; o < cases.size(); ++o)
        for (const SpecialStyle* type : typesPresent) {
          std::vector<size_t> idx;
          std::vector<Eigen::Vector2d> px;
          for (size_t i = 0; i < marks.size(); ++i)
            if (!labelled[i] && marks[i].ordinal == o && marks[i].type == type) {
              idx.push_back(i);
              px.push_back(f.pixel(marks[i].x, marks[i].y));
              drawn[i] = false;
            }
          for (size_t k : thinned(px, kThinPixels)) {
            drawn[idx[k]] = true;
            occupied.fill({px[k].x() - 2.0, px[k].y() - 2.0, px[k].x() + 2.0, px[k].y() + 2.0});
          }
        }
    }
    occupied.finish();

    // merge the labels of one case's points drawn at the same place
    std::vector<std::vector<std::string>> parts;
    for (size_t i = 0; i < marks.size(); ++i) {
      if (!labelled[i]) continue;
      const Mark& m = marks[i];
      const Eigen::Vector2d px = f.pixel(m.x, m.y);
      size_t k = 0;
      const double merge = summary ? kSummaryMergePixels : kMergePixels;
      while (k < labels.size() && (labelOrdinal[k] != m.ordinal || (labels[k].anchor - px).norm() > merge)) ++k;
      if (k == labels.size()) {
        labels.emplace_back();
        labels.back().anchor = px;
        labels.back().priority = summary ? int(m.rank) : 0;
        labelOrdinal.push_back(m.ordinal);
        parts.emplace_back();
      }
      labels[k].priority = std::min(labels[k].priority, summary ? int(m.rank) : 0);
      if (std::find(parts[k].begin(), parts[k].end(), m.label) == parts[k].end()) parts[k].push_back(m.label);
    }
    for (size_t k = 0; k < labels.size(); ++k) labels[k].text = mergedLabel(parts[k], summary);
    placeLabels(labels, f, occupied, summary ? kSummaryLabelRings : kLabelRings);
  }

  /// NAME.dat (the series), NAME_special.dat, NAME_labels.dat and NAME_jumps.dat.
  void writeData(const fs::path& dir) {
    data.write(dir / (stem + ".dat"));
    // special points: blocks per (case, type); labels: one block per case with
    //   x y label_x label_y "text" leader_x leader_y   (leader NaN when the label sits at its point)
    BlockFile sp, lab;
    for (size_t o = 0; o < cases.size(); ++o)
      for (const SpecialStyle* type : typesPresent)
        for (bool small : {false, true}) {
          size_t count = 0, shown = 0;
          for (size_t i = 0; i < marks.size(); ++i)
            if (marks[i].ordinal == o && marks[i].type == type && labelled[i] != small) ++count, shown += drawn[i];
          if (shown == 0) continue;
          const int block = sp.begin();
          std::string comment =
              "# case " + std::to_string(cases[o]) + " (" + escape::commentText(run.cases[cases[o]].label) + "): " + type->label();
          if (small)
            comment += " unlabelled, " + std::to_string(shown) + " of " + std::to_string(count) +
                       " drawn (the others within " + num(kThinPixels) + " px of one drawn)";
          sp.text(comment);
          for (size_t i = 0; i < marks.size(); ++i)
            if (marks[i].ordinal == o && marks[i].type == type && labelled[i] != small && drawn[i]) {
              // full-size markers of other types close by: both smaller (label_layout.h, markerRadius)
              std::vector<Eigen::Vector2d> others;
              for (size_t k = 0; k < marks.size() && !small; ++k)
                if (labelled[k] && marks[k].type != type) others.push_back(f.pixel(marks[k].x, marks[k].y));
              const double r = markerRadius(f.pixel(marks[i].x, marks[i].y), others, kMarkerPixels, 0.45 * kMarkerPixels);
              sp.point({marks[i].x, marks[i].y, small ? 0.5 : kMarkerSize * r / kMarkerPixels});
            }
          specialBlocks.push_back({block, o, type, small});
        }
    labelBlocks.assign(cases.size(), -1);
    for (size_t o = 0; o < cases.size(); ++o) {
      bool any = false;
      for (size_t k = 0; k < labels.size(); ++k) any = any || (labelOrdinal[k] == o && labels[k].shown);
      if (!any) continue;
      labelBlocks[o] = lab.begin();
      lab.text("# case " + std::to_string(cases[o]) + ": x y label_x label_y \"label\" leader_x leader_y");
      for (size_t k = 0; k < labels.size(); ++k) {
        if (labelOrdinal[k] != o || !labels[k].shown) continue;
        const PlacedLabel& l = labels[k];
        const Eigen::Vector2d p = f.data(l.anchor), c = f.data(l.centre), e = f.data(l.leaderEnd);
        const double nan = std::numeric_limits<double>::quiet_NaN();
        std::ostringstream line;
        line << num(p.x()) << " " << num(p.y()) << " " << num(c.x()) << " " << num(c.y()) << " " << escape::datField(l.text) << " "
             << num(l.leader ? e.x() : nan) << " " << num(l.leader ? e.y() : nan);
        lab.text(line.str());
      }
    }
    if (!marks.empty()) {
      sp.write(dir / (stem + "_special.dat"));
      lab.write(dir / (stem + "_labels.dat"));
    }
    if (anyJump) jumps.write(dir / (stem + "_jumps.dat"));
  }

  /// The gnuplot script: the series, the jumps, the markers and labels, and the key.
  void writeScript(Script& s) {
    header(s, spec.title.empty() ? (spec.type == PlotType::Stiffness ? "Loaded stiffness along the branches"
                                                                     : "Bifurcation diagram: stable solid, unstable dashed")
                                 : spec.title);
    s.body << "set key samplen 4\n";
    if (summary)
      s.body << "set key title \"labelled: branch points\\nof the primary branch\\n(BP k: mode k), jumps,\\nfirst "
                "fold per branch;\\nkey: count per type\" left\n";
    s.body << "set xlabel " << quote(parameterColumnLabel(scene, spec.x)) << "\n";
    std::string ylabel;
    for (size_t j = 0; j < ny; ++j) ylabel += (j ? ", " : "") + columnLabel(spec.y[j], scene.units);
    if (ny > 1) {
      bool same = true;
      for (const std::string& y : spec.y) same = same && (y[0] == spec.y[0][0]);
      if (same && spec.y[0][0] == 'K') ylabel = "stiffness" + scene.units.suffix(Dimension::Stiffness);
      if (same && spec.y[0][0] == 'q') ylabel = "joint angles (rad)";
    }
    s.body << "set ylabel " << quote(ylabel) << "\n";
    s.body << "# ranges and margins fixed so that the special-point labels (placed by buckle, "
           << stem << "_labels.dat) do not overlap\n";
    f.script(s.body);
    s.body << "plot \\\n";
    bool first = true;
    auto clause = [&](const std::string& c) {
      s.body << (first ? "  " : ", \\\n  ") << c;
      first = false;
    };
    // one key entry per case (and column): its stable curve; stability itself is explained by
    // the two entries that follow
    const bool perSeriesKey = multiCase || ny > 1;
    bool anyStable = false, anyUnstable = false, anyDisconnected = false;
    for (const Series& se : series) {
      (se.stable ? anyStable : anyUnstable) = (se.stable ? anyStable : anyUnstable) || se.any;
      anyDisconnected = anyDisconnected || (se.disconnected && se.any);
      std::string title;
      if (perSeriesKey && se.stable && !se.disconnected) {
        if (multiCase) title = run.cases[cases[se.ordinal]].label;
        if (ny > 1) title += (title.empty() ? "" : " ") + spec.y[se.yIdx];
      }
      clause(quote(stem + ".dat") + " index " + std::to_string(se.block) + " using 1:2 with lines lw " +
             num(look.width) + " lc rgb " +
             quote(withAlpha(se.disconnected ? kDisconnectedColor : seriesColor(se.ordinal, se.yIdx),
                             se.stable ? look.alphaStable : look.alphaUnstable)) +
             " dt " + (se.stable ? "1" : "2") +
             (title.empty() ? std::string(" notitle") : " title " + quote(title) + " noenhanced"));
    }
    const std::string keyColor = perSeriesKey ? std::string("black") : seriesColor(0, 0);
    if (anyStable || !anyUnstable) clause("keyentry with lines lw 2 dt 1 lc rgb " + quote(keyColor) + " title 'stable'");
    if (anyUnstable) clause("keyentry with lines lw 2 dt 2 lc rgb " + quote(keyColor) + " title 'unstable'");
    if (anyDisconnected)
      clause("keyentry with lines lw 2 dt 1 lc rgb " + quote(kDisconnectedColor) +
             " title 'disconnected branch'");
    if (anyJump) {
      clause(quote(stem + "_jumps.dat") + " index 1 using 1:2 with lines lw 1.5 lc rgb '#ff7f0e' notitle");
      clause(quote(stem + "_jumps.dat") +
             " index 0 using 1:2:3:4 with vectors head filled size screen 0.015,20 lw 1.5 lc rgb '#ff7f0e' title 'jump'");
    }
    if (!marks.empty()) {
      // leader lines under the markers
      for (size_t o = 0; o < cases.size(); ++o)
        if (labelBlocks[o] >= 0)
          clause(quote(stem + "_labels.dat") + " index " + std::to_string(labelBlocks[o]) +
                 " using 1:2:($6-$1):($7-$2) with vectors nohead lw 0.8 lc rgb '#777777' notitle");
      // a summary's small markers first, under the labelled ones
      for (bool small : {true, false})
        for (const SpecialBlock& b : specialBlocks) {
          if (b.small != small) continue;
          const SpecialStyle& st = *b.type;
          const std::string at = quote(stem + "_special.dat") + " index " + std::to_string(b.block) + " using 1:2:3";
          if (small) {
            clause(at + " with points pt " + std::to_string(st.point) + " ps variable lc rgb " + quote(st.color) + " notitle");
            continue;
          }
          const std::string fill = summary ? st.color : multiCase ? color(b.ordinal * ny) : std::string("black");
          clause(at + " with points pt " + std::to_string(st.point) + " ps variable lc rgb " + quote(fill) + " notitle");
          clause(at + " with points pt " + std::to_string(st.point - 1) + " ps variable lw 1 lc rgb 'black' notitle");
        }
      for (const SpecialStyle* type : typesPresent) {
        const SpecialStyle& st = *type;
        const std::string title = st.key;
        if (summary)
          clause("keyentry with points pt " + std::to_string(st.point) + " ps 1.2 lc rgb " + quote(st.color) + " title " +
                 quote(title + " (" + std::to_string(records[type]) + ")") + " noenhanced");
        else
          clause("keyentry with points pt " + std::to_string(st.point) + " ps 1.4 lc rgb 'black' title " + quote(title) +
                 " noenhanced");
      }
      for (size_t o = 0; o < cases.size(); ++o)
        if (labelBlocks[o] >= 0)
          clause(quote(stem + "_labels.dat") + " index " + std::to_string(labelBlocks[o]) +
                 " using 3:4:5 with labels center font ',9' tc rgb " +
                 quote(multiCase ? color(o * ny) : std::string("black")) + " noenhanced notitle");
    }
    s.body << "\n";
  }

  const Scene& scene;
  const RunResult& run;
  const PlotSpec& spec;
  const std::vector<size_t> cases;
  const bool multiCase;
  const size_t ny;
  const std::string stem;

  BlockFile data, jumps;
  std::vector<Series> series;
  std::vector<std::vector<Eigen::Vector2d>> polylines;  // in data coordinates, for the label placement
  double xlo = std::numeric_limits<double>::infinity(), xhi = -xlo, ylo = xlo, yhi = -xlo;
  std::vector<double> ys;  // a stiffness plot's values, framed without the run-up to its poles
  std::vector<Mark> marks;
  std::map<const SpecialStyle*, size_t> records;  // special points per type over the plot's cases (the key's counts)
  bool summary = false;
  BranchLook look;
  std::vector<bool> labelled;  // per mark
  bool anyJump = false;
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> arrows;
  Frame f;
  std::vector<const SpecialStyle*> typesPresent;  // in the order of specialStyles()
  Occupancy occupied{1, 1};
  std::vector<bool> drawn;  // per mark: a summary's unlabelled marker drawn (not thinned out)
  std::vector<PlacedLabel> labels;
  std::vector<size_t> labelOrdinal;
  std::vector<SpecialBlock> specialBlocks;
  std::vector<int> labelBlocks;  // per case: its block in NAME_labels.dat (−1: none)
};

}  // namespace

void branchPlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s) {
  BranchPlot(scene, run, spec).draw(dir, s);
}

}  // namespace buckle::scene::plot_detail
