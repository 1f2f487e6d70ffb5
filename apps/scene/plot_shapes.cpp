// The chain's shapes at chosen path values (triangles, springs, joints, limits and contacts, one
// panel per case and value), the sudden load's snapshots and every equilibrium of the
// `equilibria` analysis drawn the same way.
#include "scene/plot_internal.h"

namespace buckle::scene::plot_detail {

namespace {

// ---- chain shapes ------------------------------------------------------------------------------

/// The pixels of one panel of the `shapes` grid.
const Eigen::Vector2d kShapePanel(600.0, 440.0);

/// Tick steps of a panel drawn to scale (`set size ratio -1`): one step on both axes, about 90
/// pixels apart on the panel's drawn scale, so that the numbers of a long chain's panel never
/// run into each other.
void panelTics(std::ostream& os, const Eigen::AlignedBox2d& box, const Eigen::Vector2d& panel) {
  const Eigen::Vector2d extent = box.sizes();
  const double scale = std::min(0.8 * panel.x() / extent.x(), 0.7 * panel.y() / extent.y());  // pixels per unit
  const double raw = 90.0 / scale, decade = std::pow(10.0, std::floor(std::log10(raw)));
  const double r = raw / decade, step = decade * (r <= 1.0 ? 1.0 : r <= 2.0 ? 2.0 : r <= 5.0 ? 5.0 : 10.0);
  os << "set xtics " << num(step) << "\nset ytics " << num(step) << "\n";
}

/// Below this many pixels per segment a chain is drawn as its centre line (base, joints, end):
/// the triangles, springs and joint-limit arcs of a 50-segment chain across a 500-pixel panel
/// (8 px a segment) would fill it with ink and hide the shape.
constexpr double kDetailedSegmentPixels = 14.0;

/// Whether a chain is drawn in detail in a panel of `panel` pixels (width, height) showing the
/// data box `box` to scale (`set size ratio -1`: the scale is the smaller of the two ratios).
bool detailedChain(const mechanics::Chain& chain, const Eigen::AlignedBox2d& box, const Eigen::Vector2d& panel) {
  const Eigen::Vector2d extent = box.sizes();
  const double scale = std::min(0.8 * panel.x() / extent.x(), 0.7 * panel.y() / extent.y());
  return chain.size() == 0 || scale * chain.length() / double(chain.size()) >= kDetailedSegmentPixels;
}

// Outline of one chain at joint angles q: triangles (closed polygons), springs (zigzags),
// joint-limit arcs; appended to the given block files. `touch`: where the chain has gone through
// the clamp's wall or through itself (contact_geometry.h: the deepest vertex / the crossing).
// Not `detailed` (a long chain, kDetailedSegmentPixels): `triangles` gets the centre line alone
// and springs and limits stay empty; joints within 5 % of a limit are still marked.
void drawChain(const mechanics::Chain& chain, const Eigen::VectorXd& q, BlockFile& triangles, BlockFile& springs,
               BlockFile& limits, BlockFile& joints, BlockFile& nearLimit, BlockFile* touch = nullptr,
               bool detailed = true, BlockFile* wall = nullptr) {
  // a vertex within 1e-9 of the chain's length of x = 0 rests on the wall (held there by the
  // contact, wall_contact.h), two links within it rest on each other (self_contact.h); deeper is
  // through
  const double onWall = 1e-9 * chain.length();
  const mechanics::SelfClearance self =
      touch || wall ? mechanics::selfClearance(chain, q) : mechanics::SelfClearance{};
  if (touch) {
    const mechanics::BaseClearance base = mechanics::baseClearance(chain, q);
    if (base.distance < -onWall) touch->point({base.point.x(), base.point.y()});
    if (self.distance < -onWall) touch->point({self.point.x(), self.point.y()});
  }
  if (wall) {
    std::vector<mechanics::WallVertex> on;
    for (mechanics::WallApproach a = mechanics::nearestWallVertex(chain, q); std::abs(a.distance) <= onWall;
         a = mechanics::nearestWallVertex(chain, q, on)) {
      wall->point({a.point.x(), a.point.y()});
      on.push_back(a.vertex);
    }
    if (std::abs(self.distance) <= onWall) wall->point({self.point.x(), self.point.y()});
  }
  const int n = chain.size();
  const Eigen::Matrix2Xd P = mechanics::jointPositions(chain, q);
  // joint i within 5 % of its range from a limit
  auto nearLimitAt = [&](int i) {
    const double lo = chain.lowerLimits()[i], hi = chain.upperLimits()[i];
    return std::min(hi - q[i], q[i] - lo) / (hi - lo) < 0.05;
  };
  if (!detailed) {
    for (Eigen::Index j = 0; j < P.cols(); ++j) triangles.point({P(0, j), P(1, j)});
    triangles.breakLine();
    for (int i = 0; i < n; ++i) {
      joints.point({P(0, i + 1), P(1, i + 1)});
      if (nearLimitAt(i)) nearLimit.point({P(0, i + 1), P(1, i + 1)});
    }
    return;
  }
  double theta = 0.0;
  auto dir = [](double t) { return Eigen::Vector2d(std::cos(t), std::sin(t)); };
  auto nrm = [](double t) { return Eigen::Vector2d(-std::sin(t), std::cos(t)); };
  for (int i = 0; i < n; ++i) {
    const mechanics::SegmentParameters& p = chain.segment(i).parameters();
    const Eigen::Vector2d joint = P.col(i + 1);
    const double before = theta, after = theta + q[i];
    // proximal triangle: apex at the joint, base b1 behind it, half-height a1
    const Eigen::Vector2d A1 = joint - p.b1 * dir(before) + p.a1 * nrm(before);
    const Eigen::Vector2d B1 = joint - p.b1 * dir(before) - p.a1 * nrm(before);
    const Eigen::Vector2d A2 = joint + p.b2 * dir(after) + p.a2 * nrm(after);
    const Eigen::Vector2d B2 = joint + p.b2 * dir(after) - p.a2 * nrm(after);
    for (const auto& tri : {std::array<Eigen::Vector2d, 3>{joint, A1, B1}, std::array<Eigen::Vector2d, 3>{joint, A2, B2}}) {
      for (const auto& v : tri) triangles.point({v.x(), v.y()});
      triangles.point({tri[0].x(), tri[0].y()});
      triangles.breakLine();
    }
    // springs: zigzag between the +n vertices (spring 1) and the −n vertices (spring 2)
    for (const auto& [P, Q] : {std::pair{A1, A2}, std::pair{B1, B2}}) {
      const Eigen::Vector2d d = Q - P;
      const double len = d.norm();
      const Eigen::Vector2d t = len > 0 ? Eigen::Vector2d(d / len) : Eigen::Vector2d(1, 0);
      const Eigen::Vector2d m(-t.y(), t.x());
      const int zig = 10;
      springs.point({P.x(), P.y()});
      for (int k = 1; k < zig; ++k) {
        const double f = double(k) / zig;
        const double w = (k % 2 ? 1.0 : -1.0) * 0.08 * std::max(p.b1, p.b2);
        const Eigen::Vector2d v = P + f * d + w * m;
        springs.point({v.x(), v.y()});
      }
      springs.point({Q.x(), Q.y()});
      springs.breakLine();
    }
    // joint-limit arc: admissible directions of the distal link, radius 0.6 b
    const double r = 0.6 * std::min(p.b1, p.b2);
    const double lo = chain.lowerLimits()[i], hi = chain.upperLimits()[i];
    for (int k = 0; k <= 40; ++k) {
      const double a = before + lo + (hi - lo) * k / 40.0;
      limits.point({joint.x() + r * std::cos(a), joint.y() + r * std::sin(a)});
    }
    limits.breakLine();
    for (double a : {before + lo, before + hi}) {
      limits.point({joint.x(), joint.y()});
      limits.point({joint.x() + 1.3 * r * std::cos(a), joint.y() + 1.3 * r * std::sin(a)});
      limits.breakLine();
    }
    joints.point({joint.x(), joint.y()});
    if (nearLimitAt(i)) nearLimit.point({joint.x(), joint.y()});
    theta = after;
  }
}

/// The plot command of one chain drawn by drawChain (files BASE_{lim,tri,spr,jnt,near}.dat),
/// the clamped base a hatched wall over the panel's whole height (the half-plane x ≤ 0: a chain
/// may rest on it anywhere); `under`: a plot clause drawn first, beneath the chain. Not
/// `detailed`: the centre line, and only the joints near a limit marked (small red rings).
void chainPanel(std::ostream& os, const std::string& base, double L, const std::string& under = std::string(),
                bool touch = false, bool detailed = true) {
  os << "set object 1 rect from first " << num(-0.1 * L) << ", graph 0 to first 0, graph 1"
     << " fc rgb '#bbbbbb' fs pattern 4 border lc rgb '#555555'\n";
  const std::string touchClause =
      touch ? ", \\\n  " + quote(base + "_touch.dat") + " using 1:2 with points pt 3 ps 3 lw 2 lc rgb 'magenta'" +
                  ", \\\n  " + quote(base + "_wall.dat") + " using 1:2 with points pt 9 ps 2.5 lc rgb '#2ca02c'"
            : std::string();
  os << "plot " << (under.empty() ? std::string() : under + ", \\\n  ");
  if (detailed)
    os << quote(base + "_lim.dat") << " using 1:2 with lines lc rgb '#aaaaaa' lw 1, \\\n"
       << "  " << quote(base + "_tri.dat")
       << " using 1:2 with filledcurves closed fc rgb '#c6dbef' fs solid 1.0 border lc rgb '#08306b', \\\n"
       << "  " << quote(base + "_tri.dat") << " using 1:2 with lines lc rgb '#08306b' lw 1.5, \\\n"
       << "  " << quote(base + "_spr.dat") << " using 1:2 with lines lc rgb '#e6550d' lw 1.5, \\\n"
       << "  " << quote(base + "_jnt.dat") << " using 1:2 with points pt 7 ps 0.9 lc rgb 'black', \\\n"
       << "  " << quote(base + "_near.dat") << " using 1:2 with points pt 6 ps 2.5 lw 2 lc rgb 'red'";
  else
    os << quote(base + "_tri.dat") << " using 1:2 with lines lc rgb '#08306b' lw 2, \\\n"
       << "  " << quote(base + "_near.dat") << " using 1:2 with points pt 6 ps 1 lw 1.5 lc rgb 'red'";
  os << touchClause << "\n";
  os << "unset object 1\n";
}

/// The files chainPanel draws (BASE_{tri,spr,lim,jnt,near,touch,wall}.dat) of the chain at q; each
/// starts with a NaN point so that gnuplot reads an empty panel (q null) without complaint.
void writeChainFiles(const mechanics::Chain& chain, const Eigen::VectorXd* q, const fs::path& dir,
                     const std::string& base, bool detailed) {
  BlockFile tri, spr, lim, jnt, near, touch, wall;
  for (BlockFile* f : {&tri, &spr, &lim, &jnt, &near, &touch, &wall}) {
    f->begin();
    f->point({std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()});
    f->breakLine();
  }
  if (q) drawChain(chain, *q, tri, spr, lim, jnt, near, &touch, detailed, &wall);
  for (const auto& [file, suffix] : {std::pair<BlockFile*, const char*>{&tri, "_tri"}, {&spr, "_spr"}, {&lim, "_lim"},
                                     {&jnt, "_jnt"}, {&near, "_near"}, {&touch, "_touch"}, {&wall, "_wall"}})
    file->write(dir / (base + suffix + ".dat"));
}

/// "contact: joint 3U 5L" for a panel title; a long chain's many locked joints are counted.
std::string lockedTitle(const std::string& locked) {
  const size_t joints = size_t(std::count(locked.begin(), locked.end(), ' ')) + 1;
  return joints <= 4 ? ",  contact: joint " + locked : ",  contact: " + std::to_string(joints) + " joints locked";
}

void drawShapesPlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, size_t plotIndex, const fs::path& dir,
                Script& s, std::vector<std::string>& notes) {
  const std::string stem = spec.name;
  const size_t nc = spec.cases.size(), na = spec.at.size();
  // a grid of panels of a readable size: up to three a row (four levels: two by two), more levels
  // wrap onto further rows of the same case
  const size_t cols = na <= 3 ? std::max<size_t>(na, 1) : na == 4 ? 2 : 3, rowsPerCase = (na + cols - 1) / cols;
  s.width = int(kShapePanel.x() * double(cols));
  s.height = std::min<int>(4800, int(kShapePanel.y() * double(nc * rowsPerCase)) + 60);

  // per case, the point drawn at each requested level (null: not drawn, `missing` says why)
  std::vector<std::vector<const mechanics::PointReport*>> chosenOf;
  std::vector<std::vector<std::string>> missingOf;
  for (size_t c : selected(spec)) {
    const CaseResult& cr = run.cases[c];
    const std::string& parameter = scene.cases[c].path.parameter;
    // the traced stable range, and the sampling of the parameter along the branches
    double lo = std::numeric_limits<double>::infinity(), hi = -lo, spacing = 0.0;
    for (size_t i = 0; i < cr.points.size(); ++i) {
      const mechanics::PointReport& p = cr.points[i];
      if (p.stable) lo = std::min(lo, p.parameter), hi = std::max(hi, p.parameter);
      if (i > 0 && cr.points[i - 1].branch == p.branch)
        spacing = std::max(spacing, std::abs(p.parameter - cr.points[i - 1].parameter));
    }
    const double slack = 1e-9 * std::max(std::abs(lo), std::abs(hi));
    std::vector<const mechanics::PointReport*>& chosen = chosenOf.emplace_back();
    std::vector<std::string>& missing = missingOf.emplace_back(na);
    for (size_t k = 0; k < na; ++k) {
      const double at = spec.at[k];
      // the stable point nearest to the requested level; among equals, the most deflected
      const mechanics::PointReport* best = nullptr;
      double bestD = std::numeric_limits<double>::infinity();
      for (const mechanics::PointReport& p : cr.points) {
        if (!p.stable) continue;
        const double d = std::abs(p.parameter - at) - 1e-9 * p.q.cwiseAbs().sum();
        if (d < bestD) {
          bestD = d;
          best = &p;
        }
      }
      // a requested level with no stable point traced there is reported, not moved to the
      // nearest point: outside the traced stable range, or in a gap of it wider than the
      // branches' parameter sampling
      std::ostringstream why;
      if (!best)
        why << "no stable point was traced";
      else if (at < lo - slack || at > hi + slack)
        why << "outside the traced stable range [" << num(lo) << ", " << num(hi) << "]";
      else if (std::abs(best->parameter - at) > spacing + slack)
        why << "no stable point traced there (nearest stable " << parameter << " = " << num(best->parameter) << ")";
      if (!why.str().empty()) {
        missing[k] = why.str();
        best = nullptr;
        std::ostringstream note;
        note << "plot \"" << spec.name << "\"" << (nc > 1 ? ", case \"" + cr.label + "\"" : std::string())
             << ": shape requested at " << parameter << " = " << num(at) << " (/plots/" << plotIndex << "/at/" << k
             << ") not drawn: " << missing[k];
        notes.push_back(note.str());
      }
      chosen.push_back(best);
    }
  }

  // each panel to its own scale: the chain drawn there (and the base) fills it, true to its
  // aspect ratio; a margin of 1.2 b around it (b the mean half-length: a chain is 2 b n long), or
  // 3 % of a long chain's extent
  auto boxOf = [&](size_t o, const mechanics::PointReport* p) {
    const CaseResult& cr = run.cases[size_t(spec.cases[o])];
    Eigen::AlignedBox2d box;
    box.extend(Eigen::Vector2d(0.0, 0.0));
    if (p) {
      const Eigen::Matrix2Xd P = mechanics::jointPositions(cr.chain, p->q);
      for (Eigen::Index j = 1; j < P.cols(); ++j) box.extend(Eigen::Vector2d(P.col(j)));
    } else {  // nothing drawn: a panel of the usual proportions for the message, not a strip
      box.extend(Eigen::Vector2d(cr.chain.length(), 0.35 * cr.chain.length()));
      box.extend(Eigen::Vector2d(0.0, -0.35 * cr.chain.length()));
    }
    const double pad = std::max(1.2 * cr.chain.length() / (2.0 * std::max(1, cr.chain.size())), 0.03 * box.sizes().maxCoeff());
    box.extend(Eigen::Vector2d(box.min().array() - pad));
    box.extend(Eigen::Vector2d(box.max().array() + pad));
    box.extend(Eigen::Vector2d(-0.1 * cr.chain.length(), box.min().y()));  // the base's wall
    return box;
  };
  bool detailed = true;
  for (size_t o = 0; o < nc; ++o)
    for (size_t k = 0; k < na; ++k)
      detailed = detailed && detailedChain(run.cases[size_t(spec.cases[o])].chain, boxOf(o, chosenOf[o][k]), kShapePanel);
  s.body << "set encoding utf8\nset size ratio -1\nunset key\nset grid lc rgb '#eeeeee'\nset tics font ',9'\n";
  s.body << "set multiplot layout " << nc * rowsPerCase << "," << cols << " title "
         << quote(!spec.title.empty() ? spec.title
                  : detailed ? std::string("Chain shapes" + scene.units.suffix(Dimension::Length) + ", each panel to its own scale\ngrey arcs: "
                                           "joint limits, red: joint within 5% of a limit, green: vertex held on the wall or another link, magenta star: through the clamp or itself")
                             : std::string("Chain shapes" + scene.units.suffix(Dimension::Length) + ", each panel to its own scale, centre lines "
                                           "(base, joints, end)\nred: joint within 5% of a limit, green: vertex held on the wall or another link, magenta star: through the clamp or itself"))
         << " font ',11'\n";
  for (size_t o = 0; o < nc; ++o) {
    const size_t c = size_t(spec.cases[o]);
    const CaseResult& cr = run.cases[c];
    const std::string& parameter = scene.cases[c].path.parameter;
    for (size_t k = 0; k < na; ++k) {
      const mechanics::PointReport* p = chosenOf[o][k];
      const std::string base = stem + "_" + std::to_string(c) + "_" + std::to_string(k);
      writeChainFiles(cr.chain, p ? &p->q : nullptr, dir, base, detailed);
      std::ostringstream title;
      if (p) {
        // five significant digits, in the scene's unit
        const std::string unit = scene.units.unit(columnDimension(parameter));
        title << (nc > 1 ? cr.label + ": " : std::string()) << parameter << " = " << short5(p->parameter)
              << (unit.empty() ? "" : " " + unit);
        // the nearest traced point is drawn; the title says when it differs from the request
        // beyond the title's rounding (relative to the path's range)
        const PathSpec& path = scene.cases[c].path;
        if (std::abs(p->parameter - spec.at[k]) > 1e-5 * std::max(std::abs(path.from), std::abs(path.to)))
          title << " (asked " << num(spec.at[k]) << ")";
        if (p->haveStiffness && std::isfinite(p->K(0, 0)))
          title << ",  K_{xx} = " << short5(p->K(0, 0)) << ", K_{yy} = " << short5(p->K(1, 1))
                << " " << scene.units.unit(Dimension::Stiffness);
        if (!p->locked.label().empty()) title << lockedTitle(p->locked.label());  // joints locked at a limit
        if (!p->locked.wallLabel().empty()) title << ",  on the wall: " << p->locked.wallLabel();  // vertices held on the wall
        if (!p->locked.selfLabel().empty()) title << ",  held: " << p->locked.selfLabel();  // self contacts
      } else {
        title << (nc > 1 ? cr.label + ": " : std::string()) << parameter << " = " << num(spec.at[k]) << ": not drawn";
        s.body << "set label 1 " << quote(missingOf[o][k]) << " at graph 0.5, graph 0.5 center font ',9' noenhanced\n";
      }
      const double L = cr.chain.length();
      const Eigen::AlignedBox2d box = boxOf(o, p);
      s.body << "set title " << quote(title.str()) << " font ',10'\n";
      s.body << "set xrange [" << num(box.min().x()) << ":" << num(box.max().x()) << "]\nset yrange [" << num(box.min().y())
             << ":" << num(box.max().y()) << "]\n";
      panelTics(s.body, box, kShapePanel);
      chainPanel(s.body, base, L, std::string(), true, detailed);
      s.body << "unset label 1\n";
    }
    // the last row of a case that wraps is filled up, so that the next case starts a row
    for (size_t k = na; k < cols * rowsPerCase; ++k) s.body << "set multiplot next\n";
  }
  s.body << "unset multiplot\n";
}

// ---- sudden load --------------------------------------------------------------------------------

// Per case: the energies of the dynamic response against time (total potential Π, kinetic T,
// dissipated W_d and their sum, constant up to the integrator's balance error), then the dynamic
// rest shape beside the quasi-static one, to the same scale, over the unloaded start in grey.
void drawSuddenPlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s) {
  const std::string stem = spec.name;
  std::vector<size_t> cases;
  for (size_t c : selected(spec))
    if (run.cases[c].haveSudden) cases.push_back(c);
  const size_t rows = std::max<size_t>(1, cases.size());
  s.width = 1560;
  s.height = std::min<int>(2400, int(420 * rows) + 40);
  s.body << "set encoding utf8\nset grid lc rgb '#dddddd'\n";
  s.body << "set multiplot layout " << rows << ",3 title "
         << quote(spec.title.empty() ? std::string("Sudden load: energies of the response, rest shape beside the "
                                                   "quasi-static one")
                                     : spec.title)
         << " noenhanced font ',11'\n";
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (size_t c : cases) {
    const CaseResult& cr = run.cases[c];
    const SuddenLoadRecord& r = cr.sudden;
    const std::string& parameter = scene.cases[c].path.parameter;
    const std::string base = stem + "_" + std::to_string(c);
    // energies, full precision: Π + T + W_d is checked against the reported balance error
    {
      std::ostringstream os;
      os << "# sudden load, case " << c << " (" << escape::commentText(cr.label) << "): t potential kinetic dissipated sum\n";
      char buf[160];
      for (const mechanics::TrajectorySample& t : r.trajectory) {
        std::snprintf(buf, sizeof buf, "%.17g %.17g %.17g %.17g %.17g\n", t.t, t.potential, t.kinetic, t.dissipated,
                      t.potential + t.kinetic + t.dissipated);
        os << buf;
      }
      std::ofstream(dir / (base + "_energy.dat")) << os.str();
    }
    std::ostringstream title;
    title << (cases.size() > 1 ? cr.label + ": " : std::string()) << parameter << " = " << num(r.value)
          << " at once, " << (r.inertial ? "inertial dynamics" : "gradient flow") << "; balance error "
          << short4(r.energyBalanceError);
    s.body << "set title " << quote(title.str()) << " noenhanced font ',10'\n";
    // the response is fast and the settling slow: time on a log scale (t = 0 is the start, off it)
    double t1 = 0.0, tEnd = 0.0;
    for (const mechanics::TrajectorySample& t : r.trajectory) {
      if (t1 == 0.0 && t.t > 0.0) t1 = t.t;
      tEnd = std::max(tEnd, t.t);
    }
    s.body << "set key center right font ',9' opaque box\nset size noratio\nset autoscale xy\n"
           << "set xlabel 't (model time; log scale)'\nset ylabel " << quote("energy" + scene.units.suffix(Dimension::Moment))
           << "\n";
    if (t1 > 0.0 && tEnd > t1) s.body << "set logscale x\nset xrange [" << num(t1) << ":" << num(tEnd) << "]\nset format x '10^{%L}'\n";
    s.body << "plot " << quote(base + "_energy.dat") << " using 1:2 with lines lw 2 lc rgb '#1f77b4' title 'Π (total potential)', \\\n"
           << "  '' using 1:3 with lines lw 2 lc rgb '#d62728' title 'T (kinetic)', \\\n"
           << "  '' using 1:4 with lines lw 2 lc rgb '#2ca02c' title 'W_d (dissipated)', \\\n"
           << "  '' using 1:5 with lines lw 1.5 dt 2 lc rgb 'black' title 'Π + T + W_d'\n";

    // the two answers, one scale
    Eigen::AlignedBox2d box;
    box.extend(Eigen::Vector2d(0.0, 0.0));
    for (const Eigen::VectorXd* q : {&cr.q0, &r.rest, &r.staticShape}) {
      if (q->size() != cr.chain.size()) continue;
      const Eigen::Matrix2Xd P = mechanics::jointPositions(cr.chain, *q);
      for (Eigen::Index j = 1; j < P.cols(); ++j) box.extend(Eigen::Vector2d(P.col(j)));
    }
    // (a margin of about one triangle half-length b̄ = L / 2n, in the scene's length unit)
    const double L = cr.chain.length(), pad = std::max(1.2 * L / (2.0 * cr.chain.size()), 0.03 * box.sizes().maxCoeff());
    const bool ok[2] = {r.rest.size() == cr.chain.size(), r.haveStatic && r.staticShape.size() == cr.chain.size()};
    const bool detailed = detailedChain(cr.chain, box, Eigen::Vector2d(s.width / 3.0, 420.0));
    for (int k = 0; k < 2; ++k) {
      const Eigen::VectorXd& q = k == 0 ? r.rest : r.staticShape;
      const std::string b = base + (k == 0 ? "_rest" : "_static");
      BlockFile tri, spr, lim, jnt, near, start, startSpr, startLim, startJnt, startNear;
      for (BlockFile* f : {&tri, &spr, &lim, &jnt, &near, &start}) {
        f->begin();
        f->point({nan, nan});
        f->breakLine();
      }
      if (ok[k]) drawChain(cr.chain, q, tri, spr, lim, jnt, near, nullptr, detailed);
      if (cr.q0.size() == cr.chain.size())
        drawChain(cr.chain, cr.q0, start, startSpr, startLim, startJnt, startNear, nullptr, detailed);
      tri.write(dir / (b + "_tri.dat"));
      spr.write(dir / (b + "_spr.dat"));
      lim.write(dir / (b + "_lim.dat"));
      jnt.write(dir / (b + "_jnt.dat"));
      near.write(dir / (b + "_near.dat"));
      start.write(dir / (b + "_start.dat"));
      std::ostringstream t;
      if (k == 0) {
        t << "dynamic rest: " << (ok[0] ? (r.stable ? "stable" : "not stable") : "none")
          << (r.haveStatic ? ", Π = " + short4(r.potentialDynamic) : std::string());
        for (size_t v = 0; v < r.wall.size(); ++v) t << (v ? " " : ", on the wall: ") << r.wall[v].vertex.label();
      } else if (ok[1]) {
        t << "quasi-static: Π = " << short4(r.potentialStatic) << (r.differs ? " (differs" : " (same")
          << ", max |Δq| = " << short4(r.maxDifference) << ")";
      } else {
        t << "quasi-static: not reached";
      }
      s.body << "set title " << quote(t.str()) << " noenhanced font ',10'\n";
      s.body << "unset key\nunset logscale x\nset format x '% h'\nunset xlabel\nunset ylabel\nset size ratio -1\n";
      s.body << "set xrange [" << num(std::min(box.min().x() - pad, -0.1 * L)) << ":" << num(box.max().x() + pad)
             << "]\nset yrange [" << num(box.min().y() - pad) << ":" << num(box.max().y() + pad) << "]\n";
      chainPanel(s.body, b, L, quote(b + "_start.dat") + " using 1:2 with lines lc rgb '#bbbbbb' lw 1 dt 2", false,
                 detailed);
      s.body << "set autoscale xy\n";
    }
  }
  s.body << "unset multiplot\n";
}

// ---- every equilibrium at one state -------------------------------------------------------------

// One panel per equilibrium of the `equilibria` analysis (ascending potential, as equilibria.csv
// ranks them), a band of rows per case and value of `at`, all to one scale; a stable one on a
// green ground, its title saying so.
void drawEquilibriumShapes(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir,
                           Script& s) {
  std::vector<std::pair<size_t, size_t>> sets;  // (case, set)
  std::vector<size_t> cases;
  size_t most = 1;
  for (size_t c : selected(spec)) {
    if (!run.cases[c].equilibriumSets.empty()) cases.push_back(c);
    for (size_t k = 0; k < run.cases[c].equilibriumSets.size(); ++k) {
      sets.emplace_back(c, k);
      most = std::max(most, run.cases[c].equilibriumSets[k].found.equilibria.size());
    }
  }
  auto listOf = [&](const std::pair<size_t, size_t>& cs) -> const std::vector<mechanics::FoundEquilibrium>& {
    return run.cases[cs.first].equilibriumSets[cs.second].found.equilibria;
  };
  // each set on the rows its own equilibria need (no empty band under a set with fewer)
  const size_t cols = std::min<size_t>(most, 5);
  auto rowsOf = [&](const std::pair<size_t, size_t>& cs) { return std::max<size_t>(1, (listOf(cs).size() + cols - 1) / cols); };
  size_t rows = 0;
  for (const auto& cs : sets) rows += rowsOf(cs);
  rows = std::max<size_t>(1, rows);
  s.width = std::min<int>(3200, int(440 * cols));
  s.height = std::min<int>(4800, int(300 * rows) + 60);
  Eigen::AlignedBox2d box;
  box.extend(Eigen::Vector2d(0.0, 0.0));
  double bMean = 0.0;
  for (size_t c : cases) {
    const CaseResult& cr = run.cases[c];
    box.extend(Eigen::Vector2d(cr.chain.length(), 0.0));
    bMean = std::max(bMean, cr.chain.length() / (2.0 * cr.chain.size()));
    for (const EquilibriumSet& set : cr.equilibriumSets)
      for (const mechanics::FoundEquilibrium& e : set.found.equilibria) {
        const Eigen::Matrix2Xd P = mechanics::jointPositions(cr.chain, e.q);
        for (Eigen::Index j = 1; j < P.cols(); ++j) box.extend(Eigen::Vector2d(P.col(j)));
      }
  }
  const Eigen::Vector2d panel(double(s.width) / double(cols), double(s.height - 60) / double(rows));
  bool detailed = true;
  for (size_t c : cases) detailed = detailed && detailedChain(run.cases[c].chain, box, panel);
  const double pad = std::max(1.2 * bMean, 0.03 * box.sizes().maxCoeff());
  const double x0 = box.min().x() - pad, x1 = box.max().x() + pad, y0 = box.min().y() - pad, y1 = box.max().y() + pad;
  s.body << "set encoding utf8\nset size ratio -1\nunset key\nset grid lc rgb '#eeeeee'\n";
  s.body << "set multiplot layout " << rows << "," << cols << " title "
         << quote(!spec.title.empty() ? spec.title
                                      : "Every equilibrium found, ascending total potential, to scale" +
                                            scene.units.suffix(Dimension::Length) +
                                            "; green ground: stable, white: unstable (index: negative eigenvalues)")
         << " font ',11'\n";
  if (sets.empty()) s.body << "set label 1 'no equilibria computed' at graph 0.5, graph 0.5 center\nplot NaN\n";
  for (const auto& cs : sets) {
    const size_t c = cs.first;
    const CaseResult& cr = run.cases[c];
    const EquilibriumSet& set = cr.equilibriumSets[cs.second];
    const std::string& parameter = scene.cases[c].path.parameter;
    const std::string unit = scene.units.unit(columnDimension(parameter));
    const std::vector<mechanics::FoundEquilibrium>& list = set.found.equilibria;
    for (size_t k = 0; k < list.size(); ++k) {
      const mechanics::FoundEquilibrium& e = list[k];
      const std::string base =
          spec.name + "_" + std::to_string(c) + (cs.second > 0 ? "_at" + std::to_string(cs.second) : "") + "_" +
          std::to_string(k);
      writeChainFiles(cr.chain, &e.q, dir, base, detailed);
      std::ostringstream title;
      title << (cases.size() > 1 ? cr.label + ", " : std::string()) << "#" << k + 1 << " " << e.shape << ": "
            << (e.stable ? "STABLE" : "unstable, index " + std::to_string(e.index)) << "\nΠ = " << short5(e.potential)
            << scene.units.suffix(Dimension::Moment) << ", " << parameter << " = " << short5(set.at)
            << (unit.empty() ? "" : " " + unit);
      if (k < set.onBranch.size() && set.onBranch[k] >= 0) title << ", branch " << set.onBranch[k];
      const double L = cr.chain.length();
      s.body << "set title " << quote(title.str()) << " font ',9' noenhanced\n";
      s.body << "set xrange [" << num(std::min(x0, -0.1 * L)) << ":" << num(x1) << "]\nset yrange [" << num(y0) << ":"
             << num(y1) << "]\n";
      if (e.stable) s.body << "set object 2 rect from graph 0,0 to graph 1,1 behind fc rgb '#e5f5e0' fs solid 1.0 noborder\n";
      chainPanel(s.body, base, L, std::string(), true, detailed);
      if (e.stable) s.body << "unset object 2\n";
    }
    for (size_t k = list.size(); k < cols * rowsOf(cs); ++k) s.body << "set multiplot next\n";
  }
  s.body << "unset multiplot\n";
}

}  // namespace

void shapesPlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, size_t plotIndex, const fs::path& dir,
                Script& s, std::vector<std::string>& notes) {
  drawShapesPlot(scene, run, spec, plotIndex, dir, s, notes);
}

void suddenPlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s) {
  drawSuddenPlot(scene, run, spec, dir, s);
}

void equilibriumShapesPlot(const Scene& scene, const RunResult& run, const PlotSpec& spec, const fs::path& dir, Script& s) {
  drawEquilibriumShapes(scene, run, spec, dir, s);
}

}  // namespace buckle::scene::plot_detail
