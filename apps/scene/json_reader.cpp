#include "scene/json_reader.h"

#include <cmath>
#include <fstream>
#include <sstream>
#include <vector>

namespace buckle::scene {

using nlohmann::json;
using Pointer = json::json_pointer;

JsonInputError::JsonInputError(std::string file, std::string path, std::string message)
    : std::runtime_error(file + ": " + (path.empty() ? std::string("(document)") : path) + ": " + message),
      file_(std::move(file)),
      path_(std::move(path)),
      message_(std::move(message)) {}

std::string describeJson(const json& v) {
  if (v.is_null()) return "null";
  if (v.is_boolean()) return std::string("the boolean ") + (v.get<bool>() ? "true" : "false");
  if (v.is_number()) {
    std::ostringstream os;
    os << "the number " << v.dump();
    return os.str();
  }
  if (v.is_string()) return "the string " + v.dump();
  if (v.is_array()) return "an array";
  return "an object";
}

void JsonReader::fail(const Pointer& p, const std::string& message) const {
  throw JsonInputError(file_, p.to_string(), message);
}

void JsonReader::expected(const Pointer& p, const json& got, const std::string& what) const {
  fail(p, "expected " + what + ", got " + describeJson(got));
}

void JsonReader::requireObject(const json& v, const Pointer& p) const {
  if (!v.is_object()) expected(p, v, "an object");
}

void JsonReader::onlyKeys(const json& v, const Pointer& p, const std::set<std::string>& allowed) const {
  requireObject(v, p);
  for (auto it = v.begin(); it != v.end(); ++it) {
    if (allowed.count(it.key())) continue;
    std::string list;
    for (const std::string& k : allowed) list += (list.empty() ? "" : ", ") + k;
    fail(p / it.key(), "unknown key \"" + it.key() + "\" (allowed here: " + list + ")");
  }
}

const json& JsonReader::required(const json& v, const Pointer& p, const std::string& key) const {
  requireObject(v, p);
  if (!v.contains(key)) fail(p / key, "missing (required)");
  return v[key];
}

double JsonReader::number(const json& v, const Pointer& p) const {
  if (!v.is_number()) expected(p, v, "a number");
  const double x = v.get<double>();
  if (!std::isfinite(x)) expected(p, v, "a finite number");
  return x;
}

double JsonReader::positive(const json& v, const Pointer& p) const {
  const double x = number(v, p);
  if (!(x > 0.0)) expected(p, v, "a number > 0");
  return x;
}

double JsonReader::nonNegative(const json& v, const Pointer& p) const {
  const double x = number(v, p);
  if (x < 0.0) expected(p, v, "a number >= 0");
  return x;
}

int JsonReader::integer(const json& v, const Pointer& p, int lo, int hi) const {
  const std::string what = "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  if (!v.is_number_integer()) expected(p, v, what);
  const long long x = v.get<long long>();
  if (x < lo || x > hi) expected(p, v, what);
  return static_cast<int>(x);
}

bool JsonReader::boolean(const json& v, const Pointer& p) const {
  if (!v.is_boolean()) expected(p, v, "true or false");
  return v.get<bool>();
}

std::string JsonReader::string(const json& v, const Pointer& p) const {
  if (!v.is_string()) expected(p, v, "a string");
  return v.get<std::string>();
}

// Parses the document, keeping the JSON path of the value being read so that a syntax error
// (NaN, a missing comma) is reported where it happened.
json parseJsonDocument(const std::string& text, const std::string& file) {
  struct Frame {
    bool array = false;
    std::string key;
    long index = -1;
  };
  std::vector<Frame> stack;
  auto enterValue = [&]() {
    if (!stack.empty() && stack.back().array) ++stack.back().index;
  };
  json::parser_callback_t cb = [&](int /*depth*/, json::parse_event_t event, json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
        enterValue();
        stack.push_back({false, "", -1});
        break;
      case json::parse_event_t::array_start:
        enterValue();
        stack.push_back({true, "", -1});
        break;
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        if (!stack.empty()) stack.pop_back();
        break;
      case json::parse_event_t::key:
        if (!stack.empty()) stack.back().key = parsed.get<std::string>();
        break;
      case json::parse_event_t::value: enterValue(); break;
    }
    return true;
  };
  auto where = [&]() {
    Pointer w;
    for (const Frame& f : stack) {
      if (f.array)
        w /= std::to_string(f.index + 1);
      else if (!f.key.empty())
        w /= f.key;
    }
    return w;
  };
  try {
    return json::parse(text, cb);
  } catch (const json::out_of_range& e) {
    // a number literal outside the double range (1e999)
    throw JsonInputError(file, where().to_string(), std::string("expected a finite number (") + e.what() + ")");
  } catch (const json::parse_error& e) {
    std::string what = e.what();
    const auto pos = what.find("syntax error");
    if (pos != std::string::npos) what = what.substr(pos);
    // NaN / Infinity are not JSON: say so plainly.
    const size_t byte = e.byte > 0 ? e.byte - 1 : 0;
    for (const char* bad : {"NaN", "nan", "Infinity", "-Infinity", "inf"}) {
      const size_t b = text.rfind(bad, byte);
      if (b != std::string::npos && byte - b < 10)
        throw JsonInputError(file, where().to_string(),
                         std::string("expected a finite number, got ") + bad + " (not valid JSON)");
    }
    size_t line = 1, column = 1;
    for (size_t i = 0; i < byte && i < text.size(); ++i) {
      if (text[i] == '\n') {
        ++line;
        column = 1;
      } else {
        ++column;
      }
    }
    throw JsonInputError(file, where().to_string(),
                     "invalid JSON at line " + std::to_string(line) + ", column " + std::to_string(column) + ": " + what);
  }
}

std::string readInputFile(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw JsonInputError(file, "", "cannot open the file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

json loadJsonDocument(const std::string& file) { return parseJsonDocument(readInputFile(file), file); }

}  // namespace buckle::scene
