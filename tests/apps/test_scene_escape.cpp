// escape.h: each target's function, read back by an independent reader — gnuplot itself for
// its strings and data fields, an RFC 4180 reader for CSV, nlohmann's parser for JSON — on
// hostile strings: line breaks, quotes, backslashes, `system`, backquotes, $(…), NUL, control
// characters, invalid UTF-8 and a string of a megabyte.
#include <catch2/catch.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "scene/escape.h"
#include "scene/output.h"
#include "rfc4180.h"
#include "temp_dir.h"
#include "read_output.h"

namespace fs = std::filesystem;
namespace escape = buckle::scene::escape;
using namespace std::string_literals;

namespace {

using buckle::test::readText;

const std::string kFffd = "\xEF\xBF\xBD";

std::vector<std::string> hostileStrings() {
  std::vector<std::string> s = {
      "x\"\nsystem \"touch PWNED\"\n#",
      "a'b\"c\\d`touch PWNED`$(touch PWNED)",
      "line1\r\nline2\rline3\n",
      "nul\0inside"s,
      "\x1b[31mred\x1b[0m\x7f\x01",
      "</script><script>alert(1)</script><!--",
      "comma, \"quoted\", field",
      "trailing backslash\\",
      "\ttab\t",
      "@macro \\140 \\n literal escapes",
      "",
      "caf\xC3\xA9 \xE2\x82\xAC \xF0\x9F\x98\x80",  // valid: é € 😀
      "\xFF\xFE",
      "\xC0\x80 overlong",
      "\xED\xA0\x80 surrogate",
      "\xE2\x82 truncated",
      "\xF4\x90\x80\x80 beyond U+10FFFF",
      "\xE2\x82",  // truncated at the end
  };
  std::string big;
  while (big.size() < (1u << 20)) big += "x\"\nsystem \"touch PWNED\"\n# `touch PWNED` \xFF, ";
  s.push_back(big);
  return s;
}

fs::path escapeDir() { return buckle::test::scratchDirectory("escape"); }

/// Runs gnuplot on `script` in `dir`; true when it exited 0.
bool gnuplot(const std::string& program, const fs::path& dir, const std::string& script) {
  std::ofstream(dir / "t.gp", std::ios::binary) << script;
  const std::string cmd = "cd '" + dir.string() + "' && '" + program + "' t.gp > log.txt 2>&1";
  return std::system(cmd.c_str()) == 0;
}

bool validUtf8ByNlohmann(const std::string& s) {
  try {
    (void)nlohmann::json(s).dump();
    return true;
  } catch (const nlohmann::json::type_error&) {
    return false;
  }
}

}  // namespace

TEST_CASE("validUtf8 keeps valid text and replaces each maximal invalid subpart by U+FFFD", "[escape]") {
  CHECK(escape::validUtf8("caf\xC3\xA9 \xF0\x9F\x98\x80") == "caf\xC3\xA9 \xF0\x9F\x98\x80");
  CHECK(escape::validUtf8("\xFF\xFE") == kFffd + kFffd);
  CHECK(escape::validUtf8("\xE2\x82x") == kFffd + "x");      // a truncated sequence is one subpart
  CHECK(escape::validUtf8("\xC0\x80") == kFffd + kFffd);     // C0 is never a lead byte
  CHECK(escape::validUtf8("\xED\xA0\x80") == kFffd + kFffd + kFffd);  // surrogates are not UTF-8
  for (const std::string& s : hostileStrings()) {
    const std::string v = escape::validUtf8(s);
    CHECK(validUtf8ByNlohmann(v));
    CHECK(escape::validUtf8(v) == v);
    // the same replacement as nlohmann's own (an independent implementation)
    const std::string dumped = nlohmann::json(s).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    CHECK(nlohmann::json::parse(dumped).get<std::string>() == v);
  }
}

TEST_CASE("displayText: line breaks as LF, other control characters as U+FFFD", "[escape]") {
  CHECK(escape::displayText("a\r\nb\rc\nd\te") == "a\nb\nc\nd\te");
  CHECK(escape::displayText("\r\r\n") == "\n\n");
  CHECK(escape::displayText("nul\0\x1b\x7f"s) == "nul" + kFffd + kFffd + kFffd);
}

TEST_CASE("gnuplotString: gnuplot reads back the display text and runs nothing", "[escape]") {
  const std::string program = buckle::scene::findGnuplot();
  const fs::path dir = escapeDir() / "gnuplot";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::vector<std::string> strings = hostileStrings();
  for (const std::string& s : strings) {
    const std::string literal = escape::gnuplotString(s);
    INFO(literal.substr(0, 200));
    // one line, no byte gnuplot could take for command substitution or a line end
    CHECK(literal.find_first_of("\n\r`"s + '\0') == std::string::npos);
    CHECK(literal.front() == '"');
    CHECK(literal.back() == '"');
  }
  if (program.empty()) {
    WARN("gnuplot not found: the literals are not read back");
    return;
  }
  std::string script = "set print 'printed.txt'\n";
  for (const std::string& s : strings) script += "print " + escape::gnuplotString(s) + "\nprint '<end>'\n";
  // the same text as a title, where the issue's scene put it
  script += "set title " + escape::gnuplotString(strings[0]) + " noenhanced\n";
  REQUIRE(gnuplot(program, dir, script));
  std::string expected;
  for (const std::string& s : strings) expected += escape::displayText(s) + "\n<end>\n";
  CHECK(readText(dir / "printed.txt") == expected);
  CHECK_FALSE(fs::exists(dir / "PWNED"));
}

TEST_CASE("commentText is one line without control characters", "[escape]") {
  for (const std::string& s : hostileStrings()) {
    const std::string c = escape::commentText(s);
    CHECK(c.find_first_of("\n\r\t"s + '\0' + '\x1b' + '\x7f') == std::string::npos);
    std::string expected = escape::displayText(s);
    for (char& ch : expected)
      if (ch == '\n' || ch == '\t') ch = ' ';
    CHECK(c == expected);
  }
}

TEST_CASE("datField: gnuplot reads one label column back", "[escape]") {
  const std::string program = buckle::scene::findGnuplot();
  const fs::path dir = escapeDir() / "dat";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::vector<std::string> strings = hostileStrings();
  strings.pop_back();  // a megabyte label does not fit a gnuplot table line
  std::string data;
  std::vector<std::string> expected;
  for (size_t i = 0; i < strings.size(); ++i) {
    const std::string field = escape::datField(strings[i]);
    CHECK(field.find_first_of("\n\r\t"s + '\0') == std::string::npos);
    CHECK(field.find('"', 1) == field.size() - 1);  // gnuplot ends the field at the next quote
    data += std::to_string(i + 1) + " 1 " + field + "\n";
    std::string text = escape::displayText(strings[i]);
    for (char& ch : text) ch = ch == '"' ? '\'' : ch == '\\' ? '/' : (ch == '\n' || ch == '\t') ? ' ' : ch;
    expected.push_back(text);
  }
  if (program.empty()) {
    WARN("gnuplot not found: the data file is not read back");
    return;
  }
  std::ofstream(dir / "l.dat", std::ios::binary) << data;
  REQUIRE(gnuplot(program, dir, "set table 'table.txt'\nplot 'l.dat' using 1:2:3 with labels\nunset table\n"));
  // the table's rows: x y "label" type
  std::vector<std::string> labels;
  std::ifstream in(dir / "table.txt");
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line[0] != '#') {
      const size_t open = line.find('"'), close = line.rfind('"');
      REQUIRE(close > open);
      labels.push_back(line.substr(open + 1, close - open - 1));
    }
  CHECK(labels == expected);
}

TEST_CASE("csvField: an RFC 4180 reader gets every field back", "[escape]") {
  const std::vector<std::string> strings = hostileStrings();
  std::string text;
  for (size_t i = 0; i < strings.size(); ++i)
    text += std::to_string(i) + "," + escape::csvField(strings[i]) + "," + escape::csvField(strings[i]) + ",end\n";
  const std::vector<std::vector<std::string>> rows = buckle::test::readCsv(text);
  REQUIRE(rows.size() == strings.size());
  for (size_t i = 0; i < strings.size(); ++i) {
    const std::vector<std::string>& fields = rows[i];
    REQUIRE(fields.size() == 4);
    CHECK(fields[0] == std::to_string(i));
    std::string expected = escape::validUtf8(strings[i]);
    for (size_t k = expected.find('\0'); k != std::string::npos; k = expected.find('\0', k))
      expected.replace(k, 1, kFffd);
    CHECK(fields[1] == expected);
    CHECK(fields[2] == expected);
    CHECK(fields[3] == "end");
  }
  CHECK(escape::csvField("3U 5L") == "3U 5L");  // plain text stays unquoted
}

TEST_CASE("jsonText never throws and parses back, jsonForHtmlScript holds no '<'", "[escape]") {
  nlohmann::json doc = nlohmann::json::array();
  for (const std::string& s : hostileStrings()) doc.push_back({{"label", s}, {s.substr(0, 40), 1}});
  CHECK_THROWS(doc.dump());  // nlohmann's default: invalid UTF-8 throws
  const nlohmann::json back = nlohmann::json::parse(escape::jsonText(doc));
  const std::string script = escape::jsonForHtmlScript(doc);
  CHECK(script.find('<') == std::string::npos);
  CHECK(script.find('\n') == std::string::npos);
  CHECK(nlohmann::json::parse(script) == back);
  const std::vector<std::string> strings = hostileStrings();
  REQUIRE(back.size() == strings.size());
  for (size_t i = 0; i < strings.size(); ++i) CHECK(back[i]["label"] == escape::validUtf8(strings[i]));
}

TEST_CASE("htmlScriptSafe writes every '<' as the JSON escape u003c and keeps every other byte", "[escape]") {
  // against the character-by-character definition, '<' at the ends, in runs, and absent
  const auto reference = [](const std::string& text) {
    std::string out;
    for (char c : text) out += c == '<' ? std::string("\\u003c") : std::string(1, c);
    return out;
  };
  std::vector<std::string> cases = {"", "<", "<<", "a<b", "<a", "a<", "no angle", "</script><!--", std::string(3, '\0') + "<"};
  std::string large;
  for (int i = 0; i < 100000; ++i) large += (i % 997 == 0 ? '<' : char('a' + i % 26));
  cases.push_back(large);
  for (const std::string& s : hostileStrings()) cases.push_back(s);
  for (const std::string& s : cases) {
    INFO(s.substr(0, 40));
    CHECK(escape::htmlScriptSafe(s) == reference(s));
    // in place from an offset (the report's data written after its page's head): the head kept
    for (size_t from : {size_t(0), std::min<size_t>(1, s.size()), s.size() / 2, s.size()}) {
      std::string text = s;
      escape::makeHtmlScriptSafe(text, from);
      CHECK(text == s.substr(0, from) + reference(s.substr(from)));
    }
  }
}
