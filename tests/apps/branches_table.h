// branches.csv of a `buckle run` output as rows of column → number (empty cells NaN), for the
// scene tests that compare its columns with the library.
#pragma once

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "rfc4180.h"

namespace buckle::test {

using BranchesTable = std::vector<std::map<std::string, double>>;

inline BranchesTable readBranches(const std::filesystem::path& out) {
  std::ifstream in(out / "branches.csv");
  REQUIRE(in.good());
  std::stringstream text;
  text << in.rdbuf();
  const auto rows = readCsv(text.str());
  REQUIRE(rows.size() >= 2);
  BranchesTable t;
  for (size_t r = 1; r < rows.size(); ++r) {
    std::map<std::string, double> row;
    for (size_t c = 0; c < rows[0].size(); ++c) row[rows[0][c]] = rows[r][c].empty() ? std::nan("") : std::stod(rows[r][c]);
    t.push_back(row);
  }
  return t;
}

}  // namespace buckle::test
