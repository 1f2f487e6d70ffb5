#include "buckle/mechanics/mirror_symmetry.h"

#include <cctype>

namespace buckle::mechanics {

namespace {

// A vertex's image: the +a and −a corners trade places (wall_contact.h), the joint stays.
WallVertex mirroredVertex(const WallVertex& v) {
  return WallVertex{v.segment, v.corner == 0 ? 0 : v.corner % 2 == 1 ? v.corner + 1 : v.corner - 1};
}

// A self contact's image: its vertex's, on the same triangle's other side edge (a base edge is
// its own image).
SelfContact mirroredSelf(const SelfContact& c) {
  return SelfContact{mirroredVertex(c.vertex), TriangleEdge{c.edge.segment, c.edge.distal, c.edge.edge == 0 ? 0 : 3 - c.edge.edge}};
}

}  // namespace

continuation::Reflection mirrorSymmetry(const EquilibriumProblem& problem) {
  continuation::Reflection mirror;
  const Chain& chain = problem.chain();
  const int n = chain.size();
  if (problem.hasBodyLoads()) return mirror;  // weight and point loads: not checked for symmetry
  for (int i = 0; i < n; ++i) {
    const SegmentParameters& p = chain.segment(i).parameters();
    if (p.k1 != p.k2 || p.L1_0 != p.L2_0) return mirror;
    if (chain.lowerLimits()[i] != -chain.upperLimits()[i]) return mirror;
  }
  const EndCondition& end = problem.endCondition();
  for (int c : {1, 2})  // y and φ: zero load (or held at zero) along the whole path
    if (end.value[c] != 0.0 || problem.direction()[c] != 0.0) return mirror;
  mirror.signs = continuation::Vector::Constant(problem.dimension(), -1.0);
  const std::vector<int> held = end.heldIndices();
  for (size_t k = 0; k < held.size(); ++k)
    if (held[k] == 0) mirror.signs[n + int(k)] = 1.0;  // the x reaction is even
  mirror.text = mirrorText;
  return mirror;
}

std::string mirrorText(const std::string& text) {
  static const std::string upper = "upper", lower = "lower";
  std::string out;
  out.reserve(text.size());
  for (size_t i = 0; i < text.size();) {
    if (text.compare(i, upper.size(), upper) == 0) {
      out += lower;
      i += upper.size();
    } else if (text.compare(i, lower.size(), lower) == 0) {
      out += upper;
      i += lower.size();
    } else if (text.compare(i, 5, "[j,+]") == 0 || text.compare(i, 5, "[j,-]") == 0) {
      out += text[i + 3] == '+' ? "[j,-]" : "[j,+]";  // a self contact's side edge (self_contact.h)
      i += 5;
    } else if (i > 0 && std::isdigit(static_cast<unsigned char>(text[i - 1])) && i + 1 < text.size() &&
               (text[i] == 'p' || text[i] == 'd') && (text[i + 1] == '+' || text[i + 1] == '-')) {
      out += text[i];  // a wall vertex's label, "3d+" (wall_contact.h): its corner across the link
      out += text[i + 1] == '+' ? '-' : '+';
      i += 2;
    } else {
      out += text[i++];
    }
  }
  return out;
}

std::vector<ContactStretch> mirrored(const std::vector<ContactStretch>& stretches) {
  std::vector<ContactStretch> image;
  for (const ContactStretch& s : stretches) {
    ContactStretch m{s.firstPoint, ContactSet()};
    for (const LockedJoint& l : s.locked.joints())
      m.locked.lock(l.joint, l.side == LimitSide::Upper ? LimitSide::Lower : LimitSide::Upper);
    for (const WallVertex& v : s.locked.wall()) m.locked.touch(mirroredVertex(v));
    for (const SelfContact& c : s.locked.self()) m.locked.hold(mirroredSelf(c));
    image.push_back(m);
  }
  return image;
}

Landing mirrored(const Landing& landing) {
  Landing image = landing;
  image.q = -landing.q;
  image.F[1] = -landing.F[1];
  image.F[2] = -landing.F[2];
  image.pose[1] = -landing.pose[1];
  image.pose[2] = -landing.pose[2];
  for (JointContact& c : image.contacts) {
    c.side = -c.side;
    c.torque = -c.torque;
  }
  for (WallSupport& w : image.wall) w.vertex = mirroredVertex(w.vertex);  // the force along x is kept
  for (SelfSupport& c : image.self) c.contact = mirroredSelf(c.contact);
  image.message = mirrorText(landing.message);
  return image;
}

GeometricContact mirrored(const continuation::Reflection& mirror, const GeometricContact& contact) {
  GeometricContact image = contact;
  mirror.apply(image.u);
  // 0 − y, not −y: a point on the axis (the base link's, y = +0) stays +0 as its recomputation
  // gives it, not −0 (printed "-0" in the note)
  image.point.y() = 0.0 - contact.point.y();
  return image;
}

}  // namespace buckle::mechanics
