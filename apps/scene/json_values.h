// Numbers in the JSON outputs (special_points.json, summary.json): JSON has no NaN or infinity,
// so a value not computed (NaN) or not finite is written as null.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <nlohmann/json.hpp>

namespace buckle::scene {

inline nlohmann::json jsonNumber(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

inline nlohmann::json jsonVector(const Eigen::VectorXd& v) {
  nlohmann::json a = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(jsonNumber(v[i]));
  return a;
}

/// An end wrench (Fx, Fy, Me) and an end pose (x, y, phi), under the names of branches.csv.
inline nlohmann::json wrenchJson(const Eigen::Vector3d& F) {
  return {{"Fx", jsonNumber(F[0])}, {"Fy", jsonNumber(F[1])}, {"Me", jsonNumber(F[2])}};
}
inline nlohmann::json poseJson(const Eigen::Vector3d& p) {
  return {{"x", jsonNumber(p[0])}, {"y", jsonNumber(p[1])}, {"phi", jsonNumber(p[2])}};
}

}  // namespace buckle::scene
