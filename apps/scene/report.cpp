#include "scene/report.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <stdexcept>
#include <sstream>
#include <string>
#include <system_error>

#include "scene/escape.h"
#include "scene/output.h"
#include "scene/output_numbers.h"
#include "scene/report_page.h"
#include "scene/special_marks.h"

namespace buckle::scene {

using nlohmann::json;

namespace {

// The page embeds every traced point; numbers keep 6 significant digits (a hundred times finer
// than a pixel of the diagram) and shapes 4, so a long chain's report stays a few megabytes.
// roundedSignificant (output_numbers.h) gives the same double as snprintf + strtod (bytes of the
// page unchanged), without the locale and stdio machinery or a conversion to text.
json rounded(double v, int digits = 6) { return roundedForPage(v, digits); }

/// Joint positions flattened as [x0, y0, x1, y1, …] (4 significant digits), as dump() writes them.
void appendJoints(std::string& out, const mechanics::Chain& chain, const Eigen::VectorXd& q) {
  const Eigen::Matrix2Xd p = mechanics::jointPositions(chain, q);
  out += '[';
  for (Eigen::Index j = 0; j < p.cols(); ++j) {
    if (j > 0) out += ',';
    appendRoundedJson(out, p(0, j), 4);
    out += ',';
    appendRoundedJson(out, p(1, j), 4);
  }
  out += ']';
}

/// The same as a JSON value (a few shapes per case: the unloaded chain, the special points).
json jointsJson(const mechanics::Chain& chain, const Eigen::VectorXd& q) {
  std::string text;
  appendJoints(text, chain, q);
  return json::parse(text);  // the same doubles: dump's numbers read back exactly
}

/// A JSON array of `count` items as dump() writes it, item(i) appending the i-th.
template <class Item>
void appendArray(std::string& out, size_t count, Item&& item) {
  out += '[';
  for (size_t i = 0; i < count; ++i) {
    if (i > 0) out += ',';
    item(i);
  }
  out += ']';
}

/// A large object member written directly into the page: its key and what appends its value as
/// dump() writes it.
struct Member {
  std::string key;
  std::function<void(std::string&)> append;
};
using Members = std::vector<Member>;

void appendDumped(std::string& out, const json& v) { out += v.dump(-1, ' ', false, json::error_handler_t::replace); }

/// The object with the members of `small` and the large `members`, in the key order of
/// nlohmann::json's std::map: the text dump() writes for the whole object, appended to `out`
/// without building the large members as JSON values (a long chain's page holds millions of
/// numbers) or copying their text.
void appendObject(std::string& out, const json& small, Members members) {
  for (const auto& item : small.items())
    members.push_back({item.key(), [&value = item.value()](std::string& o) { appendDumped(o, value); }});
  std::sort(members.begin(), members.end(), [](const Member& a, const Member& b) { return a.key < b.key; });
  out += '{';
  for (size_t i = 0; i < members.size(); ++i) {
    if (i > 0) out += ',';
    appendDumped(out, json(members[i].key));
    out += ':';
    members[i].append(out);
  }
  out += '}';
}

/// At most this many shape coordinates per case: beyond it every k-th point carries its shape
/// (the page shows the nearest one that has it).
constexpr size_t kShapeBudget = 160000;
/// At most this many per-point values (columns, branch, point, stable) per case: beyond it the
/// page keeps every k-th point of each branch and its last one, so a tree of any size gives a
/// page of a few megabytes; the files beside it have every point.
constexpr size_t kPointBudget = 120000;
/// At most this many joint coordinates over a case's special points: beyond it the first ones
/// (the start branches' come first) carry their shapes.
constexpr size_t kSpecialShapeBudget = 80000;

/// At most this many special points per case: beyond it the most important ones (the diagrams'
/// ranking, special_marks.h), in their order; special_points.json beside the page has all.
constexpr size_t kSpecialBudget = 2500;

/// The points of a case the page shows (PageSelection).
struct PageSelection {
  std::vector<size_t> points;  ///< indices into CaseResult::points, in order
  size_t stride = 1;           ///< every stride-th point of each branch (and its last)
  std::vector<size_t> specials;  ///< indices into CaseResult::specials, in order
  size_t specialShapes = 0;    ///< the first this many special points shown carry their joints
};

PageSelection pageSelection(const CaseResult& cr, size_t columns) {
  PageSelection s;
  const std::vector<mechanics::PointReport>& pts = cr.points;
  const size_t perPoint = columns + 3;
  s.stride = std::max<size_t>(1, (pts.size() * perPoint + kPointBudget - 1) / kPointBudget);
  size_t first = 0;  // the first point of the current branch
  for (size_t i = 0; i < pts.size(); ++i) {
    if (i > 0 && pts[i].branch != pts[i - 1].branch) first = i;
    const bool last = i + 1 == pts.size() || pts[i + 1].branch != pts[i].branch;
    if ((i - first) % s.stride == 0 || last) s.points.push_back(i);
  }
  const std::vector<Importance> rank = importance(cr);
  for (size_t k = 0; k < cr.specials.size(); ++k) s.specials.push_back(k);
  if (s.specials.size() > kSpecialBudget) {
    std::stable_sort(s.specials.begin(), s.specials.end(), [&rank](size_t a, size_t b) { return rank[a] < rank[b]; });
    s.specials.resize(kSpecialBudget);
    std::sort(s.specials.begin(), s.specials.end());
  }
  const size_t perShape = 2 * static_cast<size_t>(cr.chain.size() + 2);
  s.specialShapes = std::min(s.specials.size(), kSpecialShapeBudget / perShape);
  return s;
}

/// About the bytes a case's data take on the page (its shown points' values and shapes, the
/// special points), so that the page is allocated once.
size_t estimatedSize(const CaseResult& cr, const PageSelection& shown, size_t columns) {
  const size_t perShape = 2 * static_cast<size_t>(cr.chain.size() + 2);
  const size_t shapes = std::min(shown.points.size() * perShape, kShapeBudget + perShape);
  return shown.points.size() * (10 * columns + 16) + 10 * shapes + shown.specials.size() * 600 +
         shown.specialShapes * perShape * 10;
}

/// Columns of branches.csv the page draws: the path parameter and every axis of the scene's
/// bifurcation and stiffness plots (and of the main diagram).
std::set<std::string> drawnColumns(const Scene& scene, const std::string& mainX, const std::string& mainY) {
  std::set<std::string> columns{"parameter", mainX, mainY};
  for (const PlotSpec& p : scene.plots)
    if (p.type == PlotType::Bifurcation || p.type == PlotType::Stiffness) {
      columns.insert(p.x);
      columns.insert(p.y.begin(), p.y.end());
    }
  return columns;
}

/// The per-point members of a case (branch, columns, point, shapes, stable), for the points
/// `shown` selects; they refer to their arguments until appended.
Members pointMembers(const CaseResult& cr, const std::set<std::string>& columns, const PageSelection& shown) {
  const std::vector<size_t>& keep = shown.points;
  auto at = [&cr, &keep](size_t k) -> const mechanics::PointReport& { return cr.points[keep[k]]; };
  auto integers = [&keep, at](auto field) {
    return [&keep, at, field](std::string& out) {
      appendArray(out, keep.size(), [&](size_t k) { out += std::to_string(field(at(k))); });
    };
  };
  Members m;
  m.push_back({"branch", integers([](const mechanics::PointReport& p) { return p.branch; })});
  m.push_back({"columns", [&cr, &columns, &keep, at](std::string& out) {
                 Members cols;
                 for (const std::string& name : columns)
                   cols.push_back({name, [&cr, &name, &keep, at](std::string& o) {
                                     appendArray(o, keep.size(),
                                                 [&](size_t k) { appendRoundedJson(o, columnValue(name, at(k), cr), 6); });
                                   }});
                 appendObject(out, json::object(), std::move(cols));
               }});
  m.push_back({"point", integers([](const mechanics::PointReport& p) { return p.index; })});
  m.push_back({"shapes", [&cr, &keep, at](std::string& out) {
                 const size_t perShape = 2 * static_cast<size_t>(cr.chain.size() + 2);
                 const size_t stride = std::max<size_t>(1, (keep.size() * perShape + kShapeBudget - 1) / kShapeBudget);
                 appendArray(out, keep.size(), [&](size_t k) {
                   if (k % stride == 0 && at(k).q.size() == cr.chain.size())
                     appendJoints(out, cr.chain, at(k).q);
                   else
                     out += "null";
                 });
               }});
  m.push_back({"stable", [&keep, at](std::string& out) {
                 appendArray(out, keep.size(), [&](size_t k) { out += at(k).stable ? '1' : '0'; });
               }});
  return m;
}

/// A case of the page's data as dump() writes it, appended to `out`.
void appendCase(std::string& out, const Scene& scene, const CaseResult& cr, size_t index, const std::set<std::string>& columns,
                     const PageSelection& shown) {
  json c;
  c["index"] = index;
  c["label"] = cr.label;
  c["segments"] = cr.chain.size();
  c["parameter"] = index < scene.cases.size() ? scene.cases[index].path.parameter : std::string("parameter");
  c["unloaded"] = jointsJson(cr.chain, cr.q0.size() == cr.chain.size() ? cr.q0
                                                                        : Eigen::VectorXd(Eigen::VectorXd::Zero(cr.chain.size())));
  json branches = json::array();
  for (const BranchRecord& b : cr.branches)
    branches.push_back(json{{"id", b.id}, {"origin", b.origin}, {"points", b.points}, {"stop", b.stopReason}});
  c["branches"] = branches;

  json specials = json::array();
  const std::vector<Importance> rank = importance(cr);  // as the gnuplot diagrams rank them
  for (size_t shownIndex = 0; shownIndex < shown.specials.size(); ++shownIndex) {
    const size_t k = shown.specials[shownIndex];
    const SpecialPointResult& s = cr.specials[k];
    const bool shape = shownIndex < shown.specialShapes;
    json e{{"type", mechanics::label(s.type)},
           {"field", fieldName(cr, s)},
           {"branch", s.branch},
           {"parameter", rounded(s.parameter, 10)},
           {"Fx", rounded(s.F[0], 10)},
           {"Fy", rounded(s.F[1], 10)},
           {"Me", rounded(s.F[2], 10)},
           {"shape", s.shape},
           {"before", s.stabilityBefore},
           {"after", s.stabilityAfter},
           {"accuracy", rounded(s.accuracy, 3)},
           {"residual", rounded(s.residual, 3)},
           {"refined", s.refined},
           {"note", s.note}};
    json values = json::object();
    for (const std::string& name : columns) values[name] = rounded(columnValue(name, s, cr), 10);
    e["values"] = values;
    e["label"] = specialLabel(s, false);
    e["label_summary"] = specialLabel(s, true);
    e["rank"] = static_cast<int>(rank[k]);
    if (shape && s.q.size() == cr.chain.size()) e["joints"] = jointsJson(cr.chain, s.q);
    if (const mechanics::Landing& l = s.landing; l.tried) {
      e["jump"] = l.success ? l.kind + (l.shape.empty() ? "" : " (" + l.shape + ")")
                            : (l.wallBlocked ? "not landed: " : "failed: ") + l.message;
      if (shape && l.q.size() == cr.chain.size()) e["jump_joints"] = jointsJson(cr.chain, l.q);
      if (l.success && l.q.size() == cr.chain.size()) {  // where the diagrams' jump arrow ends
        mechanics::SpecialPointReport to = s;
        to.q = l.q;
        to.F = l.F;
        to.pose = l.pose;
        json landing = json::object();
        for (const std::string& name : columns) landing[name] = rounded(columnValue(name, to, cr), 10);
        e["landing"] = landing;
      }
    }
    specials.push_back(e);
  }
  c["specials"] = specials;

  if (cr.haveLandscape) {
    json l;
    for (const auto& [name, samples] : {std::pair<const char*, const std::vector<mechanics::LandscapeSample>*>{
                                            "positive", &cr.landscape.positive},
                                        {"negative", &cr.landscape.negative}}) {
      json q1 = json::array(), E = json::array(), Me = json::array();
      for (const mechanics::LandscapeSample& s : *samples) {
        const bool feasible = s.status == mechanics::LandscapeStatus::Feasible;
        q1.push_back(rounded(s.q1));
        E.push_back(feasible ? rounded(s.energy) : json(nullptr));
        Me.push_back(feasible ? rounded(s.endTorque) : json(nullptr));
      }
      l[name] = json{{"q1", q1}, {"E", E}, {"Me", Me}};
    }
    json eq = json::array();
    for (const mechanics::LandscapeEquilibrium& e : cr.landscape.equilibria)
      eq.push_back(json{{"q1", rounded(e.q1)}, {"E", rounded(e.energy)}, {"stable", e.stable}, {"shape", e.shape}});
    l["equilibria"] = eq;
    l["torque"] = scene.analyses.energyCurves.torque;
    c["landscape"] = l;
  }
  if (cr.haveTorque) {
    json q = json::array(), M = json::array(), Kq = json::array(), zeros = json::array();
    for (size_t i = 0; i < cr.torque.q.size(); ++i) {
      q.push_back(rounded(cr.torque.q[i]));
      M.push_back(rounded(cr.torque.M[i]));
      Kq.push_back(rounded(cr.torque.Kq[i]));
    }
    for (const auto& [qz, st] : cr.torque.equilibria) zeros.push_back(json{{"q", rounded(qz)}, {"stable", st}});
    c["torque"] = json{{"q", q}, {"M", M}, {"Kq", Kq}, {"zeros", zeros}};
  }
  if (cr.haveSudden) {
    json t = json::array(), pot = json::array(), kin = json::array(), dis = json::array();
    for (const mechanics::TrajectorySample& s : cr.sudden.trajectory) {
      t.push_back(rounded(s.t));
      pot.push_back(rounded(s.potential));
      kin.push_back(rounded(s.kinetic));
      dis.push_back(rounded(s.dissipated));
    }
    json sudden{{"t", t}, {"potential", pot}, {"kinetic", kin}, {"dissipated", dis}, {"message", cr.sudden.message}};
    if (cr.sudden.rest.size() == cr.chain.size()) sudden["rest"] = jointsJson(cr.chain, cr.sudden.rest);
    if (cr.sudden.haveStatic && cr.sudden.staticShape.size() == cr.chain.size())
      sudden["static"] = jointsJson(cr.chain, cr.sudden.staticShape);
    c["sudden"] = sudden;
  }
  appendObject(out, c, pointMembers(cr, columns, shown));
}

const char* labelsName(PlotLabels labels) {
  return labels == PlotLabels::All ? "all" : labels == PlotLabels::Summary ? "summary" : "auto";
}

}  // namespace

json roundedForPage(double v, int digits) {
  if (!std::isfinite(v)) return nullptr;
  return roundedSignificant(v, digits);
}

std::string reportHtml(const Scene& scene, const RunResult& run, const json& specialPoints, const json& summary) {
  json data;
  data["scene"] = scene.file;
  data["description"] = scene.description;
  json facts = summary;
  facts.erase("cases");  // per-case data are below, in the page's own layout
  data["summary"] = facts;
  // labels with the scene's units (scene/units.h), made here so the page and the plots agree
  json suffix = json::object();
  for (const auto& [name, d] : {std::pair<const char*, Dimension>{"length", Dimension::Length},
                                {"force", Dimension::Force},
                                {"moment", Dimension::Moment},
                                {"stiffness", Dimension::Stiffness},
                                {"rotational_stiffness", Dimension::RotationalStiffness}})
    suffix[name] = scene.units.suffix(d);
  // the path parameter's unit (|Δλ| of the special points table)
  suffix["parameter"] = scene.cases.empty() ? std::string() : scene.units.suffix(columnDimension(scene.cases.front().path.parameter));
  data["unit_suffix"] = suffix;
  // the markers, their key and the summary's rules, as the gnuplot diagrams draw them
  json styles = json::array();
  for (const SpecialStyle& st : specialStyles())
    styles.push_back(json{{"type", st.type}, {"point", st.point}, {"key", st.key}, {"color", st.color}});
  data["marks"] = json{{"styles", styles},
                       {"summary_above", kSummaryAboveMarkers},
                       {"summary_extra", kSummaryExtraLabels},
                       {"thin_px", kThinPixels},
                       {"merge_px", kMergePixels},
                       {"summary_merge_px", kSummaryMergePixels}};
  // the text the run's last line prints for the computation's time (summary.json's total)
  data["time_text"] = secondsText(run.totalSeconds);
  // the main diagram: the scene's first bifurcation plot, else the path parameter against q1
  const PlotSpec* first = nullptr;
  for (const PlotSpec& p : scene.plots)
    if (p.type == PlotType::Bifurcation) {
      first = &p;
      break;
    }
  const std::string mainX = first ? first->x : "parameter", mainY = first ? first->y.front() : "q1";
  const std::set<std::string> columns = drawnColumns(scene, mainX, mainY);
  bool anyPoints = false;
  std::vector<PageSelection> selections;
  size_t points = 0, shownPoints = 0, specials = 0, shownSpecials = 0, shownShapes = 0, stride = 1;
  size_t pageSize = std::strlen(kReportHead) + std::strlen(kReportMiddle) + std::strlen(kReportScript) + (1 << 16);
  for (const CaseResult& cr : run.cases) {
    const PageSelection& shown = selections.emplace_back(pageSelection(cr, columns.size()));
    pageSize += estimatedSize(cr, shown, columns.size());
    anyPoints = anyPoints || !cr.points.empty();
    points += cr.pointCount();
    shownPoints += shown.points.size();
    specials += cr.specials.size();
    shownSpecials += shown.specials.size();
    shownShapes += shown.specialShapes;
    stride = std::max(stride, shown.stride * cr.pointStride);  // of the points kept (runner.h)
  }
  if (shownPoints < points || shownShapes < specials) {
    std::ostringstream os;
    os << "This page is a summary of a large run: it draws ";
    if (shownPoints < points)
      os << shownPoints << " of the " << points << " traced points (every " << stride
         << (stride == 2 ? "nd" : stride == 3 ? "rd" : "th") << " point of each branch and its last)";
    else
      os << "every traced point";
    if (shownSpecials < specials)
      os << ", " << shownSpecials << " of the " << specials
         << " special points (the primary branch's branch points, jumps and first folds first) and the shapes of "
         << shownShapes << " of them";
    else
      os << " and the shapes of " << shownShapes << " of the " << specials << " special points";
    os << ". Every point is in branches.csv and joint_angles.npy, every special point in "
          "special_points.json, beside this page.";
    data["abridged"] = os.str();
  }
  json labels = json::object();
  auto label = [&](const std::string& column) {
    labels[column] = columnLabel(column == "parameter" ? scene.cases.front().path.parameter : column, scene.units,
                                 LabelStyle::Plain);
  };
  label("parameter");
  for (const std::string& column : columns) label(column);
  for (const char* load : kEndLoadNames) label(load);  // the special points table's heads
  for (const PlotSpec& p : scene.plots) {
    if (!p.x.empty()) label(p.x);
    for (const std::string& y : p.y) label(y);
  }
  data["labels"] = labels;
  if (anyPoints)
  {
    data["main"] = json{{"x", mainX},
                        {"y", json::array({mainY})},
                        {"xlabel", mainX},
                        {"title", first && !first->title.empty() ? first->title : "Bifurcation diagram"}};
    if (first && !first->cases.empty()) data["main"]["cases"] = first->cases;
    data["main"]["labels"] = first ? labelsName(first->labels) : "auto";
  }
  else
    data["main"] = nullptr;
  json plots = json::array();
  for (const PlotSpec& p : scene.plots) {
    json e{{"type", toString(p.type)}, {"name", p.name}, {"title", p.title}, {"x", p.x},
           {"y", p.y},                    {"at", p.at},     {"xlabel", p.x}};
    if (!p.cases.empty()) e["cases"] = p.cases;
    e["labels"] = labelsName(p.labels);
    plots.push_back(e);
  }
  data["plots"] = plots;
  data["critical"] = specialPoints.contains("critical_loads") ? specialPoints["critical_loads"] : json::array();
  // under displacement control the critical loads are of the force that drives the held
  // coordinate (its reaction), not of the coordinate
  std::string criticalColumn = "parameter";
  if (!scene.cases.empty()) {
    const CaseSpec& c = scene.cases.front();
    const bool load = !c.path.control && !c.path.gravity && !c.path.task;
    if (load && c.end.condition.isHeld(static_cast<mechanics::EndCoordinate>(c.path.coordinate)))
      criticalColumn = kEndLoadNames[size_t(c.path.coordinate)];
  }
  data["critical_column"] = criticalColumn;
  std::string page;
  page.reserve(pageSize);  // the page's megabytes written once, not regrown and copied
  page += kReportHead;
  const size_t dataFrom = page.size();
  appendObject(page, data, {{"cases", [&](std::string& out) {
                               appendArray(out, run.cases.size(), [&](size_t c) {
                                 appendCase(out, scene, run.cases[c], c, columns, selections[c]);
                               });
                             }}});
  // every "<" as \u003c: nothing inside the JSON can end or change the <script> element (escape.h)
  escape::makeHtmlScriptSafe(page, dataFrom);
  page += kReportMiddle;
  page += kReportScript;
  page += kReportEnd;
  return page;
}

void writeReport(const Scene& scene, const RunResult& run, const json& specialPoints, const json& summary,
                 const std::string& dir) {
  const std::filesystem::path file = std::filesystem::path(dir) / "report.html";
  std::ofstream out(file, std::ios::binary);
  out << reportHtml(scene, run, specialPoints, summary);
  out.close();
  if (!out) throw std::runtime_error("cannot write " + file.string() + ": " + std::strerror(errno));
}

}  // namespace buckle::scene
