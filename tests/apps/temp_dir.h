// Scratch directories of the apps tests: one per test program and process under the system's
// temporary directory (the pid keeps concurrent ctest runs apart), removed when the process ends
// normally (ctest runs every test case in a process of its own: hundreds per run otherwise).
// BUCKLE_KEEP_TEST_FILES set in the environment keeps them, to look at a failure's files.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <set>
#include <string>
#include <system_error>
#include <unistd.h>

namespace buckle::test {

/// The scratch directories this process created, removed at its normal exit (a child that
/// execs or _exits does not run it).
struct ScratchDirectories {
  std::set<std::filesystem::path> created;
  ~ScratchDirectories() {
    if (std::getenv("BUCKLE_KEEP_TEST_FILES")) return;
    for (const std::filesystem::path& d : created) {
      std::error_code ignored;
      std::filesystem::remove_all(d, ignored);
    }
  }
};
inline ScratchDirectories& scratchDirectories() {
  static ScratchDirectories dirs;
  return dirs;
}

/// <tmp>/buckle_test_<tag>_<pid>, created if missing.
inline std::filesystem::path scratchDirectory(const std::string& tag) {
  const std::filesystem::path d =
      std::filesystem::temp_directory_path() / ("buckle_test_" + tag + "_" + std::to_string(::getpid()));
  if (std::filesystem::create_directories(d)) scratchDirectories().created.insert(d);
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
