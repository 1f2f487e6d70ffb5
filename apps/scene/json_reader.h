// Reading JSON input files with errors that say where: the file, the RFC 6901 path of the bad
// value (e.g. /chain/k) and what was expected. Shared by the scene parser and the regression
// baselines, so every input file of the program reports mistakes the same way.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>
#include <string>

namespace buckle::scene {

/// Bad input: the file, the JSON path of the bad value and what was expected.
class JsonInputError : public std::runtime_error {
 public:
  JsonInputError(std::string file, std::string path, std::string message);
  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }
  const std::string& message() const { return message_; }

 private:
  std::string file_, path_, message_;
};

/// Input files larger than this are refused before they are parsed (the parsed document takes
/// several times the text's size in memory). The largest scene, kMaxSegments segment objects with
/// every key given, pretty-printed, is below a third of it.
constexpr std::uintmax_t kMaxInputBytes = std::uintmax_t(64) << 20;
/// Deeper nesting is refused: no input of the program needs more than a few levels, and copying
/// or printing a document recurses once per level.
constexpr size_t kMaxJsonDepth = 64;

/// Parses `text`; a syntax error (NaN, a missing comma, a number out of range) throws a
/// JsonInputError naming the JSON path of the value being read and the line and column; so does
/// a key that appears twice in one object, and nesting deeper than kMaxJsonDepth. Linear time.
nlohmann::json parseJsonDocument(const std::string& text, const std::string& file);

/// The whole file as text (JsonInputError when it is a directory, cannot be opened or read, or
/// is larger than kMaxInputBytes).
std::string readInputFile(const std::string& file);

/// Reads and parses a whole file (JsonInputError when it cannot be opened).
nlohmann::json loadJsonDocument(const std::string& file);

/// "the number 3", "the string \"x\"", "an array": how a wrong value is shown in messages.
std::string describeJson(const nlohmann::json& v);

/// Validating accessors over one JSON document; every failure names file and JSON path.
class JsonReader {
 public:
  using json = nlohmann::json;
  using Pointer = json::json_pointer;

  explicit JsonReader(std::string file) : file_(std::move(file)) {}
  const std::string& file() const { return file_; }

  [[noreturn]] void fail(const Pointer& p, const std::string& message) const;
  [[noreturn]] void expected(const Pointer& p, const json& got, const std::string& what) const;

  void requireObject(const json& v, const Pointer& p) const;
  /// Rejects keys outside `allowed`.
  void onlyKeys(const json& v, const Pointer& p, const std::set<std::string>& allowed) const;
  /// The member `key` of the object `v` at `p`; "missing (required)" when absent.
  const json& required(const json& v, const Pointer& p, const std::string& key) const;

  double number(const json& v, const Pointer& p) const;
  double positive(const json& v, const Pointer& p) const;
  double nonNegative(const json& v, const Pointer& p) const;
  int integer(const json& v, const Pointer& p, int lo, int hi) const;
  bool boolean(const json& v, const Pointer& p) const;
  std::string string(const json& v, const Pointer& p) const;

 private:
  std::string file_;
};

}  // namespace buckle::scene
