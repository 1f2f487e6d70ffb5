// Running build/bin/buckle from the CLI tests: exit status with output captured to a file.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <sys/wait.h>
#include "build_paths.h"

namespace buckle::test {

inline const std::string kBuckle = std::string(BUCKLE_BINARY_DIR) + "/bin/buckle";

/// Runs `buckle ARGS` (a shell-quoted string) with stdout and stderr into `capture`.
inline int exitCode(const std::string& args, const std::filesystem::path& capture) {
  const std::string cmd = "'" + kBuckle + "' " + args + " > '" + capture.string() + "' 2>&1";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace buckle::test
