#include "scene/output.h"

#include "buckle/mechanics/shape_name.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "scene/branch_stream.h"
#include "scene/output_equilibria.h"
#include "scene/output_workspace.h"
#include "scene/output_numbers.h"
#include "scene/escape.h"
#include "scene/output_target.h"
#include "scene/report.h"
#include "scene/solver_settings.h"
#include "scene/special_marks.h"
#include "scene/json_values.h"

namespace buckle::scene {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

void writeText(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  out << text;
  out.close();
  if (!out) throw std::runtime_error("cannot write " + file.string() + ": " + std::strerror(errno));
}

std::string fmt(double v) {
  std::string s;
  appendCsvNumber(s, v);
  return s;
}

// branches.csv and joint_angles.npy (branch_rows.h): copied from the rows streamed as the
// branches were final (branch_stream.h), or written from the points held in memory.
void writeBranches(const Scene& scene, const RunResult& run, const fs::path& dir) {
  if (run.stream) {
    run.stream->write(dir.string());
    return;
  }
  const BranchRows layout(scene);
  std::size_t rows = 0;
  for (const CaseResult& cr : run.cases) rows += cr.points.size();
  // one string appended to (no stream, no string per number): tens of thousands of rows
  std::string os = layout.header();
  os.reserve(os.size() + rows * layout.rowBytes());
  for (size_t c = 0; c < run.cases.size(); ++c)
    for (const mechanics::PointReport& p : run.cases[c].points) layout.appendRow(os, c, run.cases[c], p);
  writeText(dir / "branches.csv", os);
  if (!layout.sideFile()) return;
  std::string bytes = layout.jointAnglesHeader(rows);
  for (const CaseResult& cr : run.cases)
    for (const mechanics::PointReport& p : cr.points) layout.appendJointAngles(bytes, p);
  writeText(dir / "joint_angles.npy", bytes);
}

/// Joints resting against their limits: 1-based joint, side, contact torque τ_c (k b²).
json contactsJson(const std::vector<mechanics::JointContact>& contacts) {
  json a = json::array();
  for (const mechanics::JointContact& c : contacts)
    a.push_back({{"joint", c.joint + 1}, {"side", c.side > 0 ? "upper" : "lower"}, {"contact_torque", jsonNumber(c.torque)}});
  return a;
}

/// Vertices resting on the base wall: the vertex (wall column spelling) and its wall force μ_v.
json wallJson(const std::vector<mechanics::WallSupport>& wall) {
  json a = json::array();
  for (const mechanics::WallSupport& v : wall) a.push_back({{"vertex", v.vertex.label()}, {"wall_force", jsonNumber(v.force)}});
  return a;
}

json selfJson(const std::vector<mechanics::SelfSupport>& self) {
  json a = json::array();
  for (const mechanics::SelfSupport& c : self)
    a.push_back({{"vertex", c.contact.vertex.label()}, {"edge", c.contact.edge.label()}, {"contact_force", jsonNumber(c.force)}});
  return a;
}

/// The contacts made and released during dynamics: the time (the model's), the joint (1-based,
/// with its side), the wall vertex or the self contact (vertex and edge), "contact" or "release",
/// the contact torque, wall force or contact force then, and an impact's kinetic-energy loss.
json contactEventsJson(const std::vector<mechanics::ContactEvent>& events) {
  json a = json::array();
  for (const mechanics::ContactEvent& e : events) {
    json j{{"t", jsonNumber(e.t)}, {"event", e.contact ? "contact" : "release"}};
    if (e.joint >= 0) {
      j["joint"] = e.joint + 1;
      j["side"] = e.side > 0 ? "upper" : "lower";
      j["contact_torque"] = jsonNumber(e.torque);
    } else if (e.self.vertex.segment >= 0) {
      j["vertex"] = e.self.vertex.label();
      j["edge"] = e.self.edge.label();
      j["contact_force"] = jsonNumber(e.torque);
    } else {
      j["vertex"] = e.vertex.label();
      j["wall_force"] = jsonNumber(e.torque);
    }
    if (e.contact) j["kinetic_lost"] = jsonNumber(e.kineticLost);
    a.push_back(j);
  }
  return a;
}

/// A special point's contacts: where the chain touches the wall or itself, the joint that locks
/// or releases (CT / RL), the vertex that reaches or leaves the wall (WC / WR) and, located on a
/// wall stretch, the forces of its vertices there.
void addContacts(const mechanics::SpecialPointReport& s, json& p) {
  if (s.contactPoint.allFinite()) p["contact_point"] = json::array({jsonNumber(s.contactPoint.x()), jsonNumber(s.contactPoint.y())});
  if (s.joint >= 0)
    p["contact"] = {{"joint", s.joint + 1}, {"contact_torque", jsonNumber(s.contactTorque)}, {"locked_after", s.lockedAfter.label()}};
  if (!s.wallVertices.empty()) {
    std::vector<mechanics::WallSupport> wall;
    for (size_t k = 0; k < s.wallVertices.size() && Eigen::Index(k) < s.wallForces.size(); ++k)
      wall.push_back({s.wallVertices[k], s.wallForces[Eigen::Index(k)]});
    p["wall"] = wallJson(wall);
  }
  if (s.vertex.segment >= 0)
    p["wall_contact"] = {{"vertex", s.vertex.label()}, {"contact_force", jsonNumber(s.contactForce)},
                         {"wall_after", s.lockedAfter.wallLabel()}};
  if (s.selfContact.vertex.segment >= 0)
    p["self_contact"] = {{"vertex", s.selfContact.vertex.label()}, {"edge", s.selfContact.edge.label()},
                         {"contact_force", jsonNumber(s.contactForce)}, {"self_after", s.lockedAfter.selfLabel()}};
}

}  // namespace

json specialPointsJson(const Scene& scene, const RunResult& run) {
  json doc;
  doc["scene"] = scene.file;
  json points = json::array(), critical = json::array(), equilibria = json::array(), torque = json::array();
  for (size_t c = 0; c < run.cases.size(); ++c) {
    const CaseResult& cr = run.cases[c];
    for (const SpecialPointResult& s : cr.specials) {
      json p;
      p["case"] = c;
      p["case_label"] = cr.label;
      p["type"] = mechanics::label(s.type);
      p["field"] = fieldName(cr, s);
      p["branch"] = s.branch;
      p["parameter"] = jsonNumber(s.parameter);
      p["loads"] = wrenchJson(s.F);
      p["position"] = poseJson(s.pose);
      p["q"] = jsonVector(s.q);
      p["shape"] = s.shape;
      p["stability_before"] = s.stabilityBefore;
      p["stability_after"] = s.stabilityAfter;
      p["accuracy"] = {{"parameter", jsonNumber(s.accuracy)}, {"residual", jsonNumber(s.residual)}, {"refined", s.refined}};
      // K_F where the report computed it (a located KMIN: the stiffness at the minimum itself)
      if (s.K.allFinite()) p["stiffness"] = {{"Kxx", jsonNumber(s.K(0, 0))}, {"Kyy", jsonNumber(s.K(1, 1))}, {"Kxy", jsonNumber(s.K(0, 1))}};
      if (!s.note.empty()) p["note"] = s.note;
      if (!cr.inputNames.empty()) {  // a task path: the inputs at the point
        json in = json::object();
        for (size_t j = 0; j < cr.inputNames.size() && Eigen::Index(j) < s.inputs.size(); ++j)
          in[cr.inputNames[j]] = jsonNumber(s.inputs[Eigen::Index(j)]);
        p["inputs"] = in;
      }
      if (s.multiplicity > 1) p["multiplicity"] = s.multiplicity;
      if (s.branchesPredicted >= 0)
        p["branches"] = {{"predicted", s.branchesPredicted}, {"found", s.branchesFound}};
      addContacts(s, p);
      if (s.koiter.valid) {  // BP: λ(ξ) = λ + aξ + bξ², ξ in rad of the unit joint-angle mode
        p["koiter_a"] = jsonNumber(s.koiter.a);
        p["koiter_b"] = jsonNumber(s.koiter.b);
        p["koiter_b_accuracy"] = jsonNumber(s.koiter.bAccuracy);
        if (s.koiter.degenerate) {  // b = 0 to its accuracy: λ = λ + c4 ξ⁴ decides
          p["koiter_c4"] = jsonNumber(s.koiter.c4);
          p["koiter_c4_accuracy"] = jsonNumber(s.koiter.c4Accuracy);
        }
        p["post_buckling"] = mechanics::postBucklingName(s.koiter);
        json imperfections = json::array();
        for (const mechanics::ImperfectionSensitivity& im : s.imperfections)
          if (im.valid) {
            json entry = {{"imperfection", im.name},
                          {"coupling", jsonNumber(im.coupling)},
                          {"exponent", jsonNumber(im.exponent)},
                          {"prefactor", jsonNumber(im.prefactor)},
                          {"sign", im.sign}};
            if (im.coordinate < 0) entry["segment"] = im.segment < 0 ? json("all") : json(im.segment + 1);
            imperfections.push_back(entry);
          }
        p["imperfection_sensitivity"] = imperfections;
      }
      if (const mechanics::Landing& l = s.landing; l.tried) {
        json j;
        j["success"] = l.success;
        j["landing"] = l.kind;
        j["message"] = l.message;
        if (l.q.size() > 0) {
          j["q"] = jsonVector(l.q);
          j["loads"] = wrenchJson(l.F);
          j["position"] = poseJson(l.pose);
          j["shape"] = l.shape;
        }
        j["energy_released"] = jsonNumber(l.energyReleased);
        j["distance"] = jsonNumber(l.distance);
        j["contacts"] = contactsJson(l.contacts);
        if (!l.wall.empty()) j["wall"] = wallJson(l.wall);  // vertices held on the base wall
        if (!l.self.empty()) j["self"] = selfJson(l.self);  // self contacts held
        if (!l.success && l.wallBlocked) j["landing"] = "not landed: " + l.message;
        p["jump_to"] = j;
      }
      points.push_back(p);
    }
    if (cr.haveCritical) {
      for (const mechanics::BucklingMode& m : cr.critical.modes) {
        json e{{"case", c}, {"case_label", cr.label}, {"load_factor", jsonNumber(m.lambda)}, {"shape", m.shape},
               {"mode", jsonVector(m.mode)}, {"shortening", jsonNumber(m.shortening)}};
        if (std::isfinite(m.mu)) e["mu"] = m.mu;
        critical.push_back(e);
      }
    }
    if (cr.haveLandscape) {
      for (const mechanics::LandscapeEquilibrium& e : cr.landscape.equilibria) {
        Eigen::VectorXd q = e.q;
        equilibria.push_back(json{{"case", c}, {"case_label", cr.label}, {"ik_branch", e.branch}, {"q1", e.q1},
                                  {"q", jsonVector(q)}, {"energy", jsonNumber(e.energy)},
                                  {"d2E_dq1", jsonNumber(e.d2Edq1)}, {"stable", e.stable}, {"shape", e.shape},
                                  {"loads", wrenchJson(e.F)}});
      }
    }
    if (cr.haveTorque)
      for (const auto& [q, stable] : cr.torque.equilibria)
        torque.push_back(json{{"case", c}, {"case_label", cr.label}, {"q", q}, {"stable", stable}});
  }
  doc["special_points"] = points;
  if (scene.analyses.criticalForces.enabled) doc["critical_loads"] = critical;
  if (scene.analyses.twoParameter.enabled) doc["critical_curves"] = criticalCurvesJson(run);
  if (scene.analyses.energyCurves.enabled) doc["energy_equilibria"] = equilibria;
  if (scene.analyses.torqueAngle.enabled) doc["torque_zeros"] = torque;
  if (scene.analyses.equilibria.enabled) doc["equilibria"] = equilibriaJson(run);
  if (scene.analyses.workspace.enabled) doc["workspace"] = workspaceJson(run);
  if (scene.analyses.suddenLoad.enabled) {
    json sudden = json::array();
    for (size_t c = 0; c < run.cases.size(); ++c) {
      const CaseResult& cr = run.cases[c];
      if (!cr.haveSudden) continue;
      const SuddenLoadRecord& r = cr.sudden;
      json e{{"case", c},
             {"case_label", cr.label},
             {"value", jsonNumber(r.value)},
             {"success", r.success},
             {"message", r.message},
             {"model", r.inertial ? "inertial" : "gradient flow"},
             {"stable", r.stable},
             {"peak_kinetic", jsonNumber(r.peakKinetic)},
             {"max_excursion", jsonNumber(r.maxExcursion)},
             {"duration", jsonNumber(r.duration)},
             {"residual", jsonNumber(r.residual)},
             {"energy_balance_error", jsonNumber(r.energyBalanceError)}};
      if (r.rest.size() > 0)
        e["rest"] = json{{"q", jsonVector(r.rest)}, {"position", poseJson(r.restPose)}, {"contacts", contactsJson(r.contacts)},
                         {"wall", wallJson(r.wall)}, {"self", selfJson(r.self)}};
      e["contact_events"] = contactEventsJson(r.events);
      if (r.haveStatic)
        e["quasi_static"] = json{{"q", jsonVector(r.staticShape)},
                                 {"position", poseJson(r.staticPose)},
                                 {"differs", r.differs},
                                 {"max_difference", jsonNumber(r.maxDifference)},
                                 {"potential_dynamic", jsonNumber(r.potentialDynamic)},
                                 {"potential_static", jsonNumber(r.potentialStatic)},
                                 {"lower", r.lower}};
      else
        e["quasi_static"] = nullptr;
      sudden.push_back(e);
    }
    doc["sudden_load"] = sudden;
  }
  return doc;
}

namespace {

void writeCurves(const Scene& scene, const RunResult& run, const fs::path& dir) {
  if (scene.analyses.suddenLoad.enabled) {
    std::ostringstream os;
    os << "case,t,potential,kinetic,dissipated,residual";
    int maxN = 0;
    for (const CaseResult& cr : run.cases) maxN = std::max(maxN, cr.chain.size());
    for (int i = 1; i <= maxN; ++i) os << ",q" << i;
    os << "\n";
    for (size_t c = 0; c < run.cases.size(); ++c)
      for (const mechanics::TrajectorySample& t : run.cases[c].sudden.trajectory) {
        os << c << ',' << fmt(t.t) << ',' << fmt(t.potential) << ',' << fmt(t.kinetic) << ',' << fmt(t.dissipated) << ','
           << fmt(t.residual);
        for (int i = 0; i < maxN; ++i) os << ',' << (i < t.q.size() ? fmt(t.q[i]) : std::string());
        os << "\n";
      }
    writeText(dir / "sudden_load.csv", os.str());
  }
  if (scene.analyses.energyCurves.enabled) {
    std::ostringstream os;
    os << "case,ik_branch,q1,status,E,dE_dq1,Me,q2,q3\n";
    for (size_t c = 0; c < run.cases.size(); ++c) {
      const CaseResult& cr = run.cases[c];
      if (!cr.haveLandscape) continue;
      for (int b : {1, -1}) {
        const auto& samples = b > 0 ? cr.landscape.positive : cr.landscape.negative;
        for (const mechanics::LandscapeSample& s : samples) {
          const char* status = s.status == mechanics::LandscapeStatus::Feasible ? "feasible"
                               : s.status == mechanics::LandscapeStatus::JointLimit ? "joint_limit"
                                                                                  : "unreachable";
          os << c << ',' << b << ',' << fmt(s.q1) << ',' << status << ',' << fmt(s.energy) << ',' << fmt(s.dEdq1)
             << ',' << fmt(s.endTorque) << ',' << fmt(s.q[1]) << ',' << fmt(s.q[2]) << "\n";
        }
      }
    }
    writeText(dir / "energy_curves.csv", os.str());
  }
  if (scene.analyses.equilibria.enabled) writeText(dir / "equilibria.csv", equilibriaCsv(run));
  if (scene.analyses.workspace.enabled) {
    writeText(dir / "workspace_map.csv", workspaceMapCsv(run));
    writeText(dir / "workspace_curves.csv", workspaceCurvesCsv(run));
  }
  if (scene.analyses.torqueAngle.enabled) {
    std::ostringstream os;
    os << "case,q,M,Kq\n";
    for (size_t c = 0; c < run.cases.size(); ++c) {
      const TorqueCurve& t = run.cases[c].torque;
      for (size_t i = 0; i < t.q.size(); ++i)
        os << c << ',' << fmt(t.q[i]) << ',' << fmt(t.M[i]) << ',' << fmt(t.Kq[i]) << "\n";
    }
    writeText(dir / "torque_angle.csv", os.str());
  }
}

}  // namespace

json summaryJson(const Scene& scene, const RunResult& run, const PlotReport& plots) {
  json doc;
  doc["generator"] = kRunGenerator;  // the marker that lets a later --out replace this directory
  doc["schema"] = kOutputSchema;
  doc["scene"] = scene.file;
  doc["description"] = scene.description;
  doc["units"] = scene.units.toJson();
  doc["complete"] = run.complete && plots.stopped.empty();
  // stopped early by the time limit or a signal: the results are what was computed until then
  doc["interrupted"] = run.interrupted || !plots.stopped.empty();
  if (run.interrupted || !plots.stopped.empty()) doc["interruption"] = run.interrupted ? run.interruption : plots.stopped;
  if (!run.problems.empty()) doc["problems"] = run.problems;
  if (!run.warnings.empty()) doc["warnings"] = run.warnings;
  doc["computed"] = run.computed;
  doc["solver"] = solverJson(scene.solver);
  doc["accuracy"] = {{"max_corrector_residual", run.worstResidual},
                     {"max_special_point_parameter_error", run.worstLocation}};
  json timings;
  for (const auto& [name, seconds] : run.timings) timings[name] = seconds;
  timings["total"] = run.totalSeconds;
  doc["timings_seconds"] = timings;
  json cases = json::array();
  for (const CaseResult& cr : run.cases) {
    json c;
    c["label"] = cr.label;
    c["segments"] = cr.chain.size();
    json segs = json::array();
    for (int i = 0; i < cr.chain.size(); ++i) {
      const mechanics::SegmentParameters& p = cr.chain.segment(i).parameters();
      segs.push_back(json{{"a1", p.a1}, {"b1", p.b1}, {"a2", p.a2}, {"b2", p.b2}, {"k1", p.k1}, {"k2", p.k2},
                          {"L1_0", p.L1_0}, {"L2_0", p.L2_0}, {"q_min", cr.chain.lowerLimits()[i]},
                          {"q_max", cr.chain.upperLimits()[i]},
                          {"straight_stiffness", cr.chain.segment(i).straightStiffness()}});
    }
    c["segment_parameters"] = segs;
    c["q0"] = jsonVector(cr.q0);
    c["start_position"] = poseJson(cr.pose0);
    c["start_parameter"] = cr.startValue;
    if (cr.qStart.size() == cr.q0.size() && cr.qStart != cr.q0) c["start_q"] = jsonVector(cr.qStart);
    if (!cr.startNote.empty()) c["start_note"] = cr.startNote;
    if (cr.loadLimit > 0.0) {
      c["load_limit"] = cr.loadLimit;
      c["load_limit_derived"] = cr.loadLimitDerived;
      if (std::isfinite(cr.firstCriticalReaction)) c["first_critical_reaction"] = cr.firstCriticalReaction;
    }
    json branches = json::array();
    for (const BranchRecord& b : cr.branches) {
      branches.push_back(json{{"id", b.id}, {"parent", b.parent}, {"origin", b.origin}, {"points", b.points},
                              {"stop", b.stopReason}, {"stop_message", b.stopMessage}, {"finished", b.finished}});
      if (!b.skipped.empty()) branches.back()["skipped"] = b.skipped;
      if (b.fromEquilibrium > 0) {  // disconnected: its seed (rank in equilibria.csv) and the branch it joins
        branches.back()["from_equilibrium"] = b.fromEquilibrium;
        branches.back()["from_equilibrium_at"] = b.fromEquilibriumAt;
        branches.back()["joins"] = b.joins >= 0 ? json(b.joins) : json(nullptr);
      }
    }
    if (scene.analyses.continuation.enabled || scene.analyses.loadHistory.enabled) c["branches"] = branches;
    if (cr.haveCritical) {
      json crit;
      crit["unloaded_stable"] = cr.critical.unloadedStable;
      json loads = json::array();
      for (const auto& m : cr.critical.modes) loads.push_back(json{{"load_factor", m.lambda}, {"shape", m.shape}});
      crit["loads"] = loads;
      if (cr.haveAnalytic) {
        const auto& a = cr.analytic;
        crit["closed_form_eq17"] = {{"kappa", a.kappa}, {"Fx_U", a.FxU}, {"Fx_Z", a.FxZ}};
        // measured error of the branch points found by continuation against eq 17
        json errors = json::object();
        for (const auto& [name, exact] : {std::pair<std::string, double>{"U", a.FxU}, {"Z", a.FxZ}}) {
          double best = std::numeric_limits<double>::infinity();
          for (const SpecialPointResult& s : cr.specials)
            if (s.type == mechanics::EventType::BranchPoint) best = std::min(best, std::abs(s.F[0] - exact));
          if (std::isfinite(best)) errors["continuation_BP_" + name] = best;
          double lin = std::numeric_limits<double>::infinity();
          for (const auto& m : cr.critical.modes) lin = std::min(lin, std::abs(m.lambda - exact));
          if (std::isfinite(lin)) errors["linear_buckling_" + name] = lin;
        }
        crit["abs_error_vs_eq17"] = errors;
      }
      c["critical_forces"] = crit;
    }
    cases.push_back(c);
  }
  doc["cases"] = cases;
  json p;
  p["gnuplot"] = plots.gnuplotFound ? json(plots.gnuplot) : json("not found: " + plots.gnuplot);
  p["files"] = plots.files;
  p["written"] = plots.written;
  if (!plots.failures.empty()) p["failures"] = plots.failures;
  if (!plots.notDrawn.empty()) p["not_drawn"] = plots.notDrawn;
  doc["plots"] = p;
  if (!plots.notes.empty()) doc["notes"] = plots.notes;
  return doc;
}

PlotReport writeOutputs(const Scene& scene, const RunResult& run, const std::string& dirName,
                        const continuation::Interrupt& stop) {
  const fs::path dir(dirName);
  // the load history's stable pieces are branches too (docs/scenes.md, `load_history`)
  if (scene.analyses.continuation.enabled || scene.analyses.loadHistory.enabled) writeBranches(scene, run, dir);
  const json specials = specialPointsJson(scene, run);
  writeText(dir / "special_points.json", escape::jsonText(specials) + "\n");
  writeCurves(scene, run, dir);
  if (scene.analyses.twoParameter.enabled) writeCriticalCurvesCsv(run, dirName);
  const PlotReport plots = drawPlots(scene, run, dirName, stop);
  const json summary = summaryJson(scene, run, plots);
  writeText(dir / "summary.json", escape::jsonText(summary) + "\n");
  writeReport(scene, run, specials, summary, dirName);
  return plots;
}

}  // namespace buckle::scene
