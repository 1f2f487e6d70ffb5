// Every options struct of both layers says what is wrong with it the same way: validate()
// returns the empty string when the settings are valid, else the rule a field breaks, the field
// named by its path as the user wrote it ("corrector.tolerance must be positive"); IsValid(why)
// is the same answer in Ceres' form (Options::IsValid). Entry points call them before any
// computation (docs/continuation.md, "Errors").
#pragma once

#include <cmath>
#include <initializer_list>
#include <string>

namespace buckle::continuation {

/// IsValid on top of validate(): true when `problem` is empty, else false with it in *why.
inline bool reportValidity(const std::string &problem, std::string *why) {
  if (why) *why = problem;
  return problem.empty();
}

/// The empty string when `holds`, else `prefix + field + " " + rule`.
inline std::string require(bool holds, const std::string &prefix, const char *field, const char *rule) {
  return holds ? std::string() : prefix + field + " " + rule;
}
inline std::string requirePositive(const std::string &prefix, const char *field, double value) {
  return require(value > 0.0 && std::isfinite(value), prefix, field, "must be positive and finite");
}
/// The first non-empty message of a list of checks (all of them evaluated).
inline std::string firstProblem(std::initializer_list<std::string> problems) {
  for (const std::string &problem : problems)
    if (!problem.empty()) return problem;
  return {};
}

}  // namespace buckle::continuation
