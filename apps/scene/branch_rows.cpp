#include "scene/branch_rows.h"

#include <charconv>
#include <limits>

#include "buckle/mechanics/shape_name.h"
#include "scene/column_values.h"
#include "scene/columns.h"
#include "scene/escape.h"
#include "scene/output_numbers.h"

namespace buckle::scene {

namespace {

void appendInteger(std::string& out, long long v) {
  char buf[24];
  const std::to_chars_result r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

}  // namespace

BranchRows::BranchRows(const Scene& scene)
    : n_(scene.maxSegments()),
      // a long chain's joint angles go to joint_angles.npy: the CSV stays a table of loads, poses
      // and stability
      sideFile_(n_ > kBranchesCsvJointColumns),
      stiffness_(scene.analyses.stiffness),
      self_(scene.analyses.continuation.enabled && scene.analyses.continuation.contact &&
            scene.analyses.continuation.self),
      frequencies_(scene.analyses.frequencies.enabled ? scene.analyses.frequencies.count : 0),
      inputs_(scene.inputColumns()) {}

std::string BranchRows::header() const {
  std::string os = "case,branch,point,parameter,Fx,Fy,Me,x,y,phi,dx,dy";
  if (sideFile_) {
    os += ",max_abs_q,sign_changes";
  } else {
    for (int i = 1; i <= n_; ++i) {
      os += ",q";
      appendInteger(os, i);
    }
  }
  os += ",stable,negative,min_eig,locked,contact_torque,wall,wall_force";
  if (self_) os += ",self,self_force";
  if (stiffness_)
    for (const std::string& column : stiffnessColumns()) os += "," + column;
  if (frequencies_ > 0)
    for (const std::string& column : frequencyColumns(frequencies_)) os += "," + column;
  for (const std::string& column : inputs_) os += "," + escape::csvField(column);  // task paths: the inputs' values
  os += '\n';
  return os;
}

void BranchRows::appendRow(std::string& os, size_t c, const CaseResult& cr, const mechanics::PointReport& p) const {
  auto field = [&os](double v) {
    os += ',';
    appendCsvNumber(os, v);
  };
  appendInteger(os, (long long)c);
  os += ',';
  appendInteger(os, p.branch);
  os += ',';
  appendInteger(os, p.index);
  field(p.parameter);
  for (int k = 0; k < 3; ++k) field(p.F[k]);
  for (int k = 0; k < 3; ++k) field(p.pose[k]);
  field(cr.pose0[0] - p.pose[0]);
  field(p.pose[1] - cr.pose0[1]);
  if (sideFile_) {
    const double qmax = p.q.size() > 0 ? p.q.cwiseAbs().maxCoeff() : 0.0;
    // sign changes of the bend, ignoring joints bent by less than 1e-9 of the largest
    field(qmax);
    os += ',';
    appendInteger(os, mechanics::signChanges(p.q, 1e-9 * qmax));
  } else {
    for (int i = 0; i < n_; ++i) {
      if (i < p.q.size())
        field(p.q[i]);
      else
        os += ',';
    }
  }
  os += p.stable ? ",1," : ",0,";
  appendInteger(os, p.negative);
  field(p.minEigenvalue);
  os += ',';
  os += escape::csvField(p.locked.label());
  field(p.contactTorque);
  os += ',';
  os += escape::csvField(p.locked.wallLabel());
  field(p.wallForces.sum());
  if (self_) {
    os += ',';
    os += escape::csvField(p.locked.selfLabel());
    field(p.selfForces.sum());
  }
  if (stiffness_)
    for (const std::string& column : stiffnessColumns()) field(stiffnessColumnValue(column, p.K, p.C, p.rotationalStiffness));
  for (int i = 0; i < frequencies_; ++i) field(i < p.omega.size() ? p.omega[i] : std::numeric_limits<double>::quiet_NaN());
  for (const std::string& column : inputs_) field(columnValue(column, p, cr));
  os += '\n';
}

void BranchRows::appendJointAngles(std::string& out, const mechanics::PointReport& p) const {
  static_assert(sizeof(double) == 8);
  if (p.q.size() == n_) {  // x86-64/ARM: little-endian
    out.append(reinterpret_cast<const char*>(p.q.data()), jointAnglesRowBytes());
    return;
  }
  for (int i = 0; i < n_; ++i) {
    const double v = i < p.q.size() ? p.q[i] : std::numeric_limits<double>::quiet_NaN();
    out.append(reinterpret_cast<const char*>(&v), sizeof v);  // x86-64/ARM: little-endian
  }
}

std::string BranchRows::jointAnglesHeader(size_t rows) const {
  std::string header = "{'descr': '<f8', 'fortran_order': False, 'shape': (" + std::to_string(rows) + ", " +
                       std::to_string(n_) + "), }";
  const size_t preamble = 10;  // magic (6), version (2), header length (2)
  header.append(63 - (preamble + header.size()) % 64, ' ');
  header += '\n';
  std::string bytes = std::string("\x93NUMPY\x01\x00", 8);
  bytes += char(header.size() & 0xff);
  bytes += char(header.size() >> 8);
  return bytes + header;
}

}  // namespace buckle::scene
