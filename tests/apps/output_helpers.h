// What a test of the output policy looks at on disk: every file's bytes, staging leftovers,
// permission bits. Shared by test_scene_output*.cpp and test_cli_output_target.cpp.
#pragma once

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <sys/stat.h>

namespace buckle::test {

/// Every path under `dir`, with the bytes of the regular files ("<dir>" for a directory,
/// "<link TARGET>" for a symbolic link, which is not followed).
inline std::map<std::string, std::string> snapshot(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    const std::string rel = fs::relative(e.path(), dir).string();
    if (e.is_symlink()) {
      files[rel] = "<link " + fs::read_symlink(e.path()).string() + ">";
    } else if (e.is_regular_file()) {
      std::ifstream in(e.path(), std::ios::binary);
      files[rel] = std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    } else {
      files[rel] = "<dir>";
    }
  }
  return files;
}

/// Entries of `dir` named like a staging directory (".NAME.tmp-XXXXXX", and its ".old").
inline int stagingLeftovers(const std::filesystem::path& dir) {
  int n = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().filename().string().find(".tmp-") != std::string::npos) ++n;
  return n;
}

/// Permission bits of `p` (symbolic links followed).
inline unsigned mode(const std::filesystem::path& p) {
  struct stat st {};
  REQUIRE(::stat(p.c_str(), &st) == 0);
  return st.st_mode & 07777u;
}

}  // namespace buckle::test
