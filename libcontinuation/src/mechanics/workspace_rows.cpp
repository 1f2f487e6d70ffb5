#include "workspace_rows.h"

#include "buckle/continuation/byte_packing.h"

namespace buckle::mechanics::detail {

namespace {

using continuation::ByteReader;
using continuation::ByteWriter;

Pose getPose(ByteReader& in) {
  const Vector pose = in.getVector();
  if (pose.size() != 3) in.fail("a pose of " + std::to_string(pose.size()) + " coordinates");
  return pose;
}

void putCell(ByteWriter& out, const WorkspaceCell& c) {
  out.put(c.u1);
  out.put(c.u2);
  out.put(std::uint8_t(c.reached ? 1 : 0));
  out.putString(c.note);
  out.putVector(c.q);
  out.putVector(c.pose);
  out.put(std::int32_t(c.negative));
  out.put(c.smallestEigenvalue);
  out.put(c.stiffness);
  out.put(std::int32_t(c.folds));
  out.put(c.residual);
}

void getCell(ByteReader& in, WorkspaceCell& c) {
  c.u1 = in.get<double>();
  c.u2 = in.get<double>();
  c.reached = in.get<std::uint8_t>() != 0;
  c.note = in.getString();
  c.q = in.getVector();
  c.pose = getPose(in);
  c.negative = in.get<std::int32_t>();
  c.smallestEigenvalue = in.get<double>();
  c.stiffness = in.get<double>();
  c.folds = in.get<std::int32_t>();
  c.residual = in.get<double>();
}

void putStart(ByteWriter& out, const CurveStart& s) {
  out.put(std::int32_t(s.condition));
  out.put(std::int32_t(s.boundary));
  out.putString(s.name);
  out.putVector(s.x);
  out.put(std::int32_t(s.fixed));
}

void getStart(ByteReader& in, CurveStart& s) {
  const auto condition = in.get<std::int32_t>();
  if (condition < 0 || condition > int(InputPlaneCurveProblem::Condition::Limit)) in.fail("an unknown curve condition");
  s.condition = InputPlaneCurveProblem::Condition(condition);
  s.boundary = in.get<std::int32_t>();
  s.name = in.getString();
  s.x = in.getVector();
  s.fixed = in.get<std::int32_t>();
}

void putCurve(ByteWriter& out, const WorkspaceCurve& c) {
  out.put(std::int32_t(c.cause));
  out.putString(c.name);
  out.putString(c.stop);
  out.put(std::uint64_t(c.points.size()));
  for (const WorkspaceCurvePoint& p : c.points) {
    out.put(p.u1);
    out.put(p.u2);
    out.putVector(p.q);
    out.putVector(p.pose);
    out.put(std::int32_t(p.negative));
    out.put(p.residual);
  }
}

void getCurve(ByteReader& in, WorkspaceCurve& c) {
  const auto cause = in.get<std::int32_t>();
  if (cause < 0 || cause > int(BoundaryCause::JointLimit)) in.fail("an unknown boundary cause");
  c.cause = BoundaryCause(cause);
  c.name = in.getString();
  c.stop = in.getString();
  const auto count = in.get<std::uint64_t>();
  c.points.clear();
  for (std::uint64_t k = 0; k < count; ++k) {
    WorkspaceCurvePoint& p = c.points.emplace_back();
    p.u1 = in.get<double>();
    p.u2 = in.get<double>();
    p.q = in.getVector();
    p.pose = getPose(in);
    p.negative = in.get<std::int32_t>();
    p.residual = in.get<double>();
  }
}

}  // namespace

std::string packWorkspaceRows(const WorkspaceMap& map, const std::vector<WorkspaceRow>& rows,
                              const std::vector<int>& which) {
  ByteWriter out;
  for (int j : which) {
    const WorkspaceRow& row = rows[size_t(j)];
    out.put(std::int32_t(j));
    for (int i = 0; i < map.count1; ++i) putCell(out, map.cell(i, j));
    out.put(std::uint64_t(row.starts.size()));
    for (const CurveStart& s : row.starts) putStart(out, s);
    out.put(std::uint8_t(row.hasEdge ? 1 : 0));
    if (row.hasEdge) putCurve(out, row.edge);
    out.putString(row.problem);
  }
  return out.release();
}

void unpackWorkspaceRows(const std::string& bytes, WorkspaceMap& map, std::vector<WorkspaceRow>& rows) {
  ByteReader in(bytes, "workspace map rows");
  while (!in.done()) {
    const auto j = in.get<std::int32_t>();
    if (j < 0 || j >= map.count2 || size_t(j) >= rows.size())
      in.fail("row " + std::to_string(j) + " is outside the grid of " + std::to_string(map.count2) + " rows");
    for (int i = 0; i < map.count1; ++i)
      getCell(in, map.cells[size_t(j) * size_t(map.count1) + size_t(i)]);
    WorkspaceRow& row = rows[size_t(j)];
    row = WorkspaceRow();
    const auto starts = in.get<std::uint64_t>();
    for (std::uint64_t k = 0; k < starts; ++k) getStart(in, row.starts.emplace_back());
    row.hasEdge = in.get<std::uint8_t>() != 0;
    if (row.hasEdge) getCurve(in, row.edge);
    row.problem = in.getString();
    row.done = true;
  }
}

}  // namespace buckle::mechanics::detail
