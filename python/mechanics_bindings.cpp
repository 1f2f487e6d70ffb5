// buckle.Segment, buckle.Chain, buckle.EndCondition and buckle.linear_buckling.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "bindings.h"
#include "buckle/mechanics/chain.h"
#include "buckle/mechanics/end_condition.h"
#include "buckle/mechanics/linear_buckling.h"
#include "buckle/mechanics/segment.h"
#include "buckle/mechanics/stiffness.h"
#include "buckle/mechanics/unloaded_shape.h"
#include "scene/report.h"
#include "scene/scene.h"

namespace buckle::python {

namespace py = pybind11;
namespace mech = buckle::mechanics;
using Eigen::VectorXd;

namespace {

const double kInf = std::numeric_limits<double>::infinity();

/// q must have one angle per segment (Eigen checks nothing in a release build).
void checkSize(const mech::Chain& chain, const VectorXd& v, const char* name) {
  if (v.size() != chain.size())
    throw std::invalid_argument(std::string(name) + " has " + std::to_string(v.size()) + " values; the chain has " +
                                std::to_string(chain.size()) + " segments");
}

mech::Wrench wrench(const VectorXd& F) {
  if (F.size() != 3) throw std::invalid_argument("F must be (Fx, Fy, Me): 3 values, got " + std::to_string(F.size()));
  return F;
}

mech::Control control(const std::string& s, const char* coordinate) {
  if (s == "load") return mech::Control::Load;
  if (s == "held") return mech::Control::Held;
  throw std::invalid_argument(std::string("EndCondition: ") + coordinate + " must be \"load\" or \"held\", got \"" + s +
                              "\"");
}

const char* controlName(mech::Control c) { return c == mech::Control::Held ? "held" : "load"; }

py::dict stiffnessDict(const mech::CartesianStiffness& s) {
  py::dict d;
  d["stiffness"] = Eigen::Matrix2d(s.stiffness);
  d["compliance"] = Eigen::Matrix2d(s.compliance);
  d["rotation_held"] = s.rotationHeld;
  d["singular"] = s.singular;
  d["rigid"] = s.rigid;
  d["positive_definite"] = s.positiveDefinite;
  d["negative_directions"] = s.negativeDirections;
  d["smallest_eigenvalue"] = s.smallestEigenvalue;
  return d;
}

/// A per-segment quantity of q as a NumPy ufunc-like function (scalar in, scalar out; arrays
/// elementwise).
template <double (mech::Segment::*F)(double) const>
py::object segmentFunction(const mech::Segment& s, py::object q) {
  // through a cpp_function so that the Python call converts q (scalar, list or array)
  return py::cpp_function(py::vectorize([&s](double x) { return (s.*F)(x); }))(q);
}

/// The call that builds this segment: Segment(a=…, b=…, k=…, L0=…) when both sides are equal, the
/// per-side keywords otherwise; user joint limits when set.
std::string segmentRepr(const mech::SegmentParameters& p) {
  std::string r = "Segment(";
  auto add = [&r](const char* key, double value) {
    r += (r.back() == '(' ? "" : ", ") + std::string(key) + "=" + formatNumber(value);
  };
  if (p.a1 == p.a2 && p.b1 == p.b2 && p.k1 == p.k2 && p.L1_0 == p.L2_0) {
    add("a", p.a1);
    add("b", p.b1);
    add("k", p.k1);
    add("L0", p.L1_0);
  } else {
    for (const auto& [key, value] : {std::pair<const char*, double>{"a1", p.a1}, {"b1", p.b1}, {"a2", p.a2},
                                     {"b2", p.b2}, {"k1", p.k1}, {"k2", p.k2}, {"L1_0", p.L1_0}, {"L2_0", p.L2_0}})
      add(key, value);
  }
  if (!std::isinf(p.qMinUser)) add("q_min", p.qMinUser);
  if (!std::isinf(p.qMaxUser)) add("q_max", p.qMaxUser);
  return r + ")";
}

}  // namespace

void bindMechanics(py::module_& m) {
  py::class_<mech::Segment>(m, "Segment",
                            "One dual-triangle segment: two rigid triangles on a passive joint (angle q), held by two "
                            "preloaded linear springs. Immutable; the parameters are validated on construction "
                            "(ValueError naming the bad one).")
      .def(py::init([](double a, double b, double k, double L0, std::optional<double> a1, std::optional<double> b1,
                       std::optional<double> a2, std::optional<double> b2, std::optional<double> k1,
                       std::optional<double> k2, std::optional<double> L1_0, std::optional<double> L2_0, double qMin,
                       double qMax) {
             // the keys of a scene's segment object, checked by the scene parser's own rules
             nlohmann::json keys{{"a", a}, {"b", b}, {"k", k}, {"L0", L0}};
             for (const auto& [key, value] : {std::pair<const char*, std::optional<double>>{"a1", a1}, {"b1", b1},
                                              {"a2", a2}, {"b2", b2}, {"k1", k1}, {"k2", k2}, {"L1_0", L1_0},
                                              {"L2_0", L2_0}})
               if (value) keys[key] = *value;
             // ±inf: no user limit; NaN is passed on to be refused
             if (!std::isinf(qMin)) keys["q_min"] = qMin;
             if (!std::isinf(qMax)) keys["q_max"] = qMax;
             try {
               return mech::Segment(scene::segmentFromKeys(keys, "Segment"));
             } catch (const scene::SceneError& e) {
               throw std::invalid_argument("Segment: " + e.path().substr(1) + ": " + e.message());
             }
           }),
           py::arg("a") = 0.5, py::arg("b") = 1.0, py::arg("k") = 1.0, py::arg("L0") = 2.25, py::kw_only(),
           py::arg("a1") = py::none(), py::arg("b1") = py::none(), py::arg("a2") = py::none(),
           py::arg("b2") = py::none(), py::arg("k1") = py::none(), py::arg("k2") = py::none(),
           py::arg("L1_0") = py::none(), py::arg("L2_0") = py::none(), py::arg("q_min") = -kInf,
           py::arg("q_max") = kInf,
           "Segment(a=0.5, b=1, k=1, L0=2.25, *, a1, b1, a2, b2, k1, k2, L1_0, L2_0, q_min, q_max): triangle "
           "half-height a and half-length b, spring stiffness k and free length L0 (both sides); the per-side "
           "keywords override them (1: proximal triangle / spring closing for q > 0). q_min/q_max: user joint "
           "limits, intersected with the geometric ones.")
      .def_property_readonly("parameters",
                             [](const mech::Segment& s) {
                               const mech::SegmentParameters& p = s.parameters();
                               py::dict d;
                               for (const auto& [key, value] :
                                    {std::pair<const char*, double>{"a1", p.a1}, {"b1", p.b1}, {"a2", p.a2},
                                     {"b2", p.b2}, {"k1", p.k1}, {"k2", p.k2}, {"L1_0", p.L1_0},
                                     {"L2_0", p.L2_0}, {"q_min", p.qMinUser}, {"q_max", p.qMaxUser}})
                                 d[key] = value;
                               return d;
                             },
                             "The parameters as a dict (a1, b1, a2, b2, k1, k2, L1_0, L2_0, user q_min, q_max).")
      .def_property_readonly("lower_limit", &mech::Segment::lowerLimit, "Joint limit (geometric ∩ user), rad.")
      .def_property_readonly("upper_limit", &mech::Segment::upperLimit, "Joint limit (geometric ∩ user), rad.")
      .def_property_readonly("straight_stiffness", &mech::Segment::straightStiffness,
                             "K_q(0): the joint stiffness of the straight segment (κ when symmetric).")
      .def("energy", &segmentFunction<&mech::Segment::energy>, py::arg("q"),
           "Spring energy E(q) = ½ Σ k (L − L⁰)²; q scalar or array (elementwise).")
      .def("torque", &segmentFunction<&mech::Segment::torque>, py::arg("q"), "Restoring torque M(q) = −dE/dq.")
      .def("stiffness", &segmentFunction<&mech::Segment::stiffness>, py::arg("q"), "Joint stiffness K_q(q) = d²E/dq².")
      .def("__repr__", [](const mech::Segment& s) { return segmentRepr(s.parameters()); });

  py::class_<mech::Chain>(m, "Chain",
                          "An n-segment planar chain with a clamped base. Joint angles q are NumPy arrays of size n; "
                          "end wrenches F = (Fx, Fy, Me); end poses (x, y, phi).")
      .def(py::init([](const std::vector<mech::Segment>& segments) {
             std::vector<mech::SegmentParameters> p;
             for (const mech::Segment& s : segments) p.push_back(s.parameters());
             return mech::Chain(p);
           }),
           py::arg("segments"), "Chain(segments): from a list of Segment (at least one; ValueError otherwise).")
      .def_static(
          "uniform",
          [](int n, const mech::Segment& segment) {
            if (n < 1) throw std::invalid_argument("n must be at least 1 segment, got " + std::to_string(n));
            return mech::Chain::uniform(n, segment.parameters());
          },
          py::arg("n"), py::arg("segment") = mech::Segment(mech::SegmentParameters()),
          "n identical segments (default: the paper's a = 0.5, b = 1, k = 1, L0 = 2.25).")
      .def_static(
          "with_unloaded_shape",
          [](const std::vector<mech::Segment>& segments, const VectorXd& q0) {
            if (q0.size() != static_cast<Eigen::Index>(segments.size()))
              throw std::invalid_argument("q0 has " + std::to_string(q0.size()) + " values for " +
                                          std::to_string(segments.size()) + " segments");
            std::vector<mech::SegmentParameters> p;
            for (const mech::Segment& s : segments) p.push_back(s.parameters());
            return mech::Chain(mech::preloadsForShape(p, q0));
          },
          py::arg("segments"), py::arg("q0"),
          "The chain whose unloaded shape is q0: each segment's free lengths L1_0, L2_0 are replaced (their sum kept) "
          "so that M(q0_i) = 0 (as a scene's `q0`).")
      .def("__len__", &mech::Chain::size)
      .def_property_readonly("n", &mech::Chain::size, "Number of segments.")
      .def_property_readonly("segments",
                             [](const mech::Chain& c) {
                               std::vector<mech::Segment> s;
                               for (int i = 0; i < c.size(); ++i) s.push_back(c.segment(i));
                               return s;
                             },
                             "The segments, as a list.")
      .def_property_readonly("parameters",
                             [](const mech::Chain& c) {
                               py::dict d;
                               auto column = [&c](double mech::SegmentParameters::*f) {
                                 VectorXd v(c.size());
                                 for (int i = 0; i < c.size(); ++i) v[i] = c.segment(i).parameters().*f;
                                 return v;
                               };
                               d["a1"] = column(&mech::SegmentParameters::a1);
                               d["b1"] = column(&mech::SegmentParameters::b1);
                               d["a2"] = column(&mech::SegmentParameters::a2);
                               d["b2"] = column(&mech::SegmentParameters::b2);
                               d["k1"] = column(&mech::SegmentParameters::k1);
                               d["k2"] = column(&mech::SegmentParameters::k2);
                               d["L1_0"] = column(&mech::SegmentParameters::L1_0);
                               d["L2_0"] = column(&mech::SegmentParameters::L2_0);
                               return d;
                             },
                             "Per-segment parameter lists as arrays: a1, b1, a2, b2, k1, k2, L1_0, L2_0.")
      .def_property_readonly("link_lengths", &mech::Chain::linkLengths,
                             "ℓ_0 … ℓ_n: base → joint 1, joint i → joint i+1, joint n → end (eq 5).")
      .def_property_readonly("lower_limits", &mech::Chain::lowerLimits, "Lower joint limits (geometric ∩ user).")
      .def_property_readonly("upper_limits", &mech::Chain::upperLimits, "Upper joint limits (geometric ∩ user).")
      .def_property_readonly("length", &mech::Chain::length, "Length of the straight chain.")
      .def(
          "unloaded_shape", [](const mech::Chain& c) { return mech::unloadedShape(c).q; },
          "q0: each joint's unloaded angle (M(q) = 0, the stable root nearest 0; NaN where there is none).")
      .def(
          "energy",
          [](const mech::Chain& c, const VectorXd& q) {
            checkSize(c, q, "q");
            return mech::energy(c, q);
          },
          py::arg("q"), "Elastic energy E(q) (eq 7).")
      .def(
          "torques",
          [](const mech::Chain& c, const VectorXd& q) {
            checkSize(c, q, "q");
            VectorXd M(c.size());
            mech::jointTorques(c, q, M);
            return M;
          },
          py::arg("q"), "Joint torques M = −∂E/∂q (eq 10/19).")
      .def(
          "joint_stiffness",
          [](const mech::Chain& c, const VectorXd& q) {
            checkSize(c, q, "q");
            VectorXd k(c.size());
            mech::jointStiffness(c, q, k);
            return k;
          },
          py::arg("q"), "Diagonal of K_q = ∂²E/∂q².")
      .def(
          "end_pose",
          [](const mech::Chain& c, const VectorXd& q) {
            checkSize(c, q, "q");
            return VectorXd(mech::endPose(c, q));
          },
          py::arg("q"), "End pose (x, y, phi).")
      .def(
          "end_jacobian",
          [](const mech::Chain& c, const VectorXd& q) {
            checkSize(c, q, "q");
            mech::ChainData data(c);
            mech::forwardKinematics(c, q, data);
            Eigen::MatrixXd J(3, c.size());
            mech::endJacobian(data, J);
            return J;
          },
          py::arg("q"), "3×n Jacobian of (x, y, phi) with respect to q (eq 11).")
      .def(
          "joint_positions",
          [](const mech::Chain& c, const VectorXd& q) {
            checkSize(c, q, "q");
            return Eigen::MatrixXd(mechanics::jointPositions(c, q).transpose());
          },
          py::arg("q"), "(n+2)×2 array: the base, the n joints and the end (x, y), in the unit of the segments' lengths.")
      .def(
          "total_potential",
          [](const mech::Chain& c, const VectorXd& q, const VectorXd& F) {
            checkSize(c, q, "q");
            return mech::totalPotential(c, q, wrench(F));
          },
          py::arg("q"), py::arg("F"), "Π = E − F·p (p the end pose).")
      .def(
          "total_potential_gradient",
          [](const mech::Chain& c, const VectorXd& q, const VectorXd& F) {
            checkSize(c, q, "q");
            VectorXd g(c.size());
            mech::totalPotentialGradient(c, q, wrench(F), g);
            return g;
          },
          py::arg("q"), py::arg("F"), "∂Π/∂q = ∂E/∂q − Jᵀ F (zero at an equilibrium).")
      .def(
          "total_potential_hessian",
          [](const mech::Chain& c, const VectorXd& q, const VectorXd& F) {
            checkSize(c, q, "q");
            Eigen::MatrixXd H(c.size(), c.size());
            mech::totalPotentialHessian(c, q, wrench(F), H);
            return H;
          },
          py::arg("q"), py::arg("F"), "Hessian of Π: K_q − K_g(F) (eq 26–27).")
      .def(
          "stiffness",
          [](const mech::Chain& c, const VectorXd& q, const VectorXd& F, bool rotationHeld) {
            checkSize(c, q, "q");
            return stiffnessDict(mech::loadedStiffness(c, q, wrench(F), rotationHeld));
          },
          py::arg("q"), py::arg("F") = VectorXd(VectorXd::Zero(3)), py::arg("rotation_held") = false,
          "Cartesian stiffness of the end position at the equilibrium (q, F) (eq 21–29): dict with the 2×2 "
          "`stiffness` K_F and `compliance` C_F (NaN where undefined), `singular`, `rigid`, `positive_definite`, "
          "`negative_directions`, `smallest_eigenvalue`.")
      .def("__repr__", [](const mech::Chain& c) { return "Chain(n=" + std::to_string(c.size()) + ")"; });

  py::class_<mech::EndCondition>(m, "EndCondition",
                                 "What is prescribed at the end: each of x, y, phi is \"load\" (a given force / "
                                 "torque) or \"held\" (a given coordinate, its reaction unknown).")
      .def(py::init([](const std::string& x, const std::string& y, const std::string& phi, const VectorXd& value) {
             mech::EndCondition e;
             e.control = {control(x, "x"), control(y, "y"), control(phi, "phi")};
             if (value.size() != 3) throw std::invalid_argument("EndCondition: value must have 3 entries");
             for (int i = 0; i < 3; ++i)
               if (!std::isfinite(value[i]))
                 throw std::invalid_argument("EndCondition: value[" + std::to_string(i) +
                                             "] must be a finite number (a load or a position), got " +
                                             formatNumber(value[i]));
             e.value = value;
             return e;
           }),
           py::arg("x") = "load", py::arg("y") = "load", py::arg("phi") = "load",
           py::arg("value") = VectorXd(VectorXd::Zero(3)),
           "EndCondition(x='load', y='load', phi='load', value=(0, 0, 0)): value holds the load (Fx, Fy, Me) of a "
           "loaded coordinate or the position of a held one.")
      .def_static("free_end", [](const VectorXd& F) { return mech::EndCondition::freeEnd(wrench(F)); },
                  py::arg("F") = VectorXd(VectorXd::Zero(3)), "Every coordinate loaded (a cantilever).")
      .def_static("clamped_pinned", &mech::EndCondition::clampedPinned, py::arg("Fx") = 0.0, py::arg("y") = 0.0,
                  "y held, rotation free, x under Fx: the clamped–pinned column (eq 14–17).")
      .def_static("held_position", &mech::EndCondition::heldPosition, py::arg("x"), py::arg("y"),
                  "End held at (x, y), rotation free.")
      .def_property_readonly("control",
                             [](const mech::EndCondition& e) {
                               return py::make_tuple(controlName(e.control[0]), controlName(e.control[1]),
                                                     controlName(e.control[2]));
                             },
                             "(x, y, phi) controls: \"load\" or \"held\".")
      .def_property_readonly("value", [](const mech::EndCondition& e) { return VectorXd(e.value); },
                             "Loads of loaded coordinates, positions of held ones.")
      .def("__repr__", [](const mech::EndCondition& e) {
        return std::string("EndCondition(x='") + controlName(e.control[0]) + "', y='" + controlName(e.control[1]) +
               "', phi='" + controlName(e.control[2]) + "', value=(" + formatNumber(e.value[0]) + ", " +
               formatNumber(e.value[1]) + ", " + formatNumber(e.value[2]) + "))";
      });

  m.def(
      "linear_buckling",
      [](const mech::Chain& chain, std::optional<VectorXd> q0, const mech::EndCondition& end, const VectorXd& direction,
         int count) {
        const VectorXd start = q0 ? *q0 : VectorXd(VectorXd::Zero(chain.size()));
        checkSize(chain, start, "q0");
        if (direction.size() != 3) throw std::invalid_argument("direction must have 3 entries (dFx, dFy, dMe)");
        mech::LinearBucklingOptions options;
        options.direction = direction;
        options.count = count;
        mech::LinearBucklingResult r;
        {
          py::gil_scoped_release release;
          r = mech::linearBuckling(chain, start, end, options);
        }
        py::list modes;
        VectorXd loads(static_cast<Eigen::Index>(r.modes.size()));
        for (size_t i = 0; i < r.modes.size(); ++i) {
          const mech::BucklingMode& b = r.modes[i];
          loads[static_cast<Eigen::Index>(i)] = b.lambda;
          py::dict d;
          d["load_factor"] = b.lambda;
          d["mode"] = b.mode;
          d["shape"] = b.shape;
          d["shortening"] = b.shortening;
          d["mu"] = b.mu;
          d["alpha1"] = b.alpha1;
          d["alpha3"] = b.alpha3;
          modes.append(d);
        }
        py::dict out;
        out["loads"] = loads;
        out["modes"] = modes;
        out["unloaded_stable"] = r.unloadedStable;
        out["degenerate"] = r.degenerate;
        out["dropped_infinite"] = r.droppedInfinite;
        out["constrained_dimension"] = r.constrainedDimension;
        return out;
      },
      py::arg("chain"), py::arg("q0") = py::none(), py::arg("end") = mech::EndCondition::clampedPinned(0.0),
      py::arg("direction") = VectorXd(Eigen::Vector3d(1.0, 0.0, 0.0)), py::arg("count") = -1,
      "Critical loads and modes of the chain at the unloaded configuration q0 (default straight) under the end "
      "load λ·direction, with the coordinates `end` holds held (its values unused). Returns a dict: `loads` "
      "(array of λ, ascending |λ|), `modes` (dicts: load_factor, mode, shape, shortening, mu, alpha1, alpha3), "
      "`unloaded_stable`, `degenerate`, `dropped_infinite`, `constrained_dimension`. ValueError when q0 is not "
      "an unloaded equilibrium.");
}

}  // namespace buckle::python
