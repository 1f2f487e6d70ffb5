// Scratch directories of the apps tests: one per test program and process under the system's
// temporary directory (the pid keeps concurrent ctest runs apart).
#pragma once

#include <filesystem>
#include <string>
#include <unistd.h>

namespace buckle::test {

/// <tmp>/buckle_test_<tag>_<pid>, created if missing.
inline std::filesystem::path scratchDirectory(const std::string& tag) {
  const std::filesystem::path d =
      std::filesystem::temp_directory_path() / ("buckle_test_" + tag + "_" + std::to_string(::getpid()));
  std::filesystem::create_directories(d);
  return d;
}

/// scratchDirectory(tag)/name with nothing at it: for an output the program under test creates.
inline std::filesystem::path absentPath(const std::string& tag, const std::string& name) {
  const std::filesystem::path d = scratchDirectory(tag) / name;
  std::filesystem::remove_all(d);
  return d;
}

/// scratchDirectory(tag)/name, empty.
inline std::filesystem::path freshDirectory(const std::string& tag, const std::string& name) {
  const std::filesystem::path d = absentPath(tag, name);
  std::filesystem::create_directories(d);
  return d;
}

}  // namespace buckle::test
