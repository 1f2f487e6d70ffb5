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

}  // namespace buckle::scene
