#include "scene/escape.h"

#include <algorithm>
#include <cstddef>
#include <cstring>

namespace buckle::scene::escape {

namespace {

const char* const kReplacement = "\xEF\xBF\xBD";  // U+FFFD

/// Length of the valid UTF-8 sequence at s[i] (1-4), or minus the length of its maximal invalid
/// subpart (at least one byte). Table 3-7 of the Unicode standard: well-formed byte sequences.
int sequenceAt(std::string_view s, std::size_t i) {
  const auto byte = [&s](std::size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char b0 = byte(i);
  if (b0 < 0x80) return 1;
  int length = 0;
  unsigned char lo = 0x80, hi = 0xBF;  // range of the second byte
  if (b0 >= 0xC2 && b0 <= 0xDF) length = 2;
  else if (b0 == 0xE0) length = 3, lo = 0xA0;
  else if ((b0 >= 0xE1 && b0 <= 0xEC) || b0 == 0xEE || b0 == 0xEF) length = 3;
  else if (b0 == 0xED) length = 3, hi = 0x9F;  // no surrogates
  else if (b0 == 0xF0) length = 4, lo = 0x90;
  else if (b0 >= 0xF1 && b0 <= 0xF3) length = 4;
  else if (b0 == 0xF4) length = 4, hi = 0x8F;  // up to U+10FFFF
  else return -1;
  for (int k = 1; k < length; ++k) {
    if (i + std::size_t(k) >= s.size()) return -k;
    const unsigned char b = byte(i + std::size_t(k));
    if (k == 1 ? (b < lo || b > hi) : (b < 0x80 || b > 0xBF)) return -k;
  }
  return length;
}

/// Calls put(valid sequence) for each character of validUtf8(s), in order.
template <typename Put>
void forEachCharacter(std::string_view s, Put put) {
  for (std::size_t i = 0; i < s.size();) {
    const int n = sequenceAt(s, i);
    put(n > 0 ? s.substr(i, std::size_t(n)) : std::string_view(kReplacement));
    i += std::size_t(n > 0 ? n : -n);
  }
}

bool isControl(std::string_view c) {
  return c.size() == 1 && (static_cast<unsigned char>(c[0]) < 0x20 || c[0] == 0x7F);
}

/// displayText(s), one character at a time: CR LF and a lone CR as LF, other controls but TAB
/// and LF as U+FFFD.
template <typename Put>
void forEachDisplayCharacter(std::string_view s, Put put) {
  bool afterCr = false;
  forEachCharacter(s, [&](std::string_view c) {
    const bool cr = c == "\r";
    if (c == "\n" && afterCr) {
      afterCr = false;
      return;  // the LF of a CR LF: its CR was written as LF
    }
    afterCr = cr;
    if (cr) put("\n");
    else if (isControl(c) && c != "\t" && c != "\n") put(kReplacement);
    else put(c);
  });
}

}  // namespace

std::string validUtf8(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  forEachCharacter(s, [&out](std::string_view c) { out += c; });
  return out;
}

std::string displayText(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  forEachDisplayCharacter(s, [&out](std::string_view c) { out += c; });
  return out;
}

std::string gnuplotString(std::string_view s) {
  std::string out = "\"";
  out.reserve(s.size() + 2);
  forEachDisplayCharacter(s, [&out](std::string_view c) {
    if (c == "\\") out += "\\\\";
    else if (c == "\"") out += "\\\"";
    else if (c == "`") out += "\\140";
    else if (c == "\n") out += "\\n";
    else if (c == "\t") out += "\\t";
    else out += c;
  });
  return out + "\"";
}

std::string commentText(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  forEachDisplayCharacter(s, [&out](std::string_view c) { out += (c == "\n" || c == "\t") ? std::string_view(" ") : c; });
  return out;
}

std::string datField(std::string_view s) {
  std::string out = "\"";
  out.reserve(s.size() + 2);
  forEachDisplayCharacter(s, [&out](std::string_view c) {
    if (c == "\"") out += '\'';
    else if (c == "\\") out += '/';
    else if (c == "\n" || c == "\t") out += ' ';
    else out += c;
  });
  return out + "\"";
}

std::string csvField(std::string_view s) {
  std::string value;
  value.reserve(s.size());
  bool quote = false;
  forEachCharacter(s, [&](std::string_view c) {
    if (c.size() == 1 && c[0] == '\0') c = kReplacement;  // many CSV readers stop at NUL
    quote = quote || c == "," || c == "\"" || c == "\r" || c == "\n";
    value += c;
  });
  if (!quote) return value;
  std::string out = "\"";
  out.reserve(value.size() + 2);
  for (char c : value) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

std::string jsonText(const nlohmann::json& doc, int indent) {
  return doc.dump(indent, ' ', /*ensure_ascii=*/false, nlohmann::json::error_handler_t::replace);
}

std::string jsonForHtmlScript(const nlohmann::json& doc) { return htmlScriptSafe(jsonText(doc, -1)); }

std::string htmlScriptSafe(std::string_view text) {
  std::string out(text);
  makeHtmlScriptSafe(out, 0);
  return out;
}

void makeHtmlScriptSafe(std::string& text, size_t from) {
  // A page's data is megabytes of text with few or no '<': rewritten only where there are some,
  // whole runs between them moved at once.
  const size_t first = text.find('<', from);
  if (first == std::string::npos) return;
  const size_t count = size_t(std::count(text.begin() + std::ptrdiff_t(first), text.end(), '<'));
  constexpr std::string_view kEscape = "\\u003c";
  size_t write = text.size() + count * (kEscape.size() - 1);
  size_t read = text.size();
  text.resize(write);
  while (read > first) {
    const size_t lt = text.rfind('<', read - 1);
    const size_t run = read - (lt + 1);
    write -= run;
    std::memmove(&text[write], &text[lt + 1], run);
    write -= kEscape.size();
    std::memcpy(&text[write], kEscape.data(), kEscape.size());
    read = lt;
  }
}

}  // namespace buckle::scene::escape
