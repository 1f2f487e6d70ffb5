// Text from a scene (plot titles, case labels, the description) written into files of other
// languages: one function per target, so that nothing a user writes can end a string, a line or
// a field early — a scene is data, never executed (a gnuplot script runs shell commands with
// `system` and with backquotes inside double-quoted strings).
//
// Every function first replaces invalid UTF-8 by U+FFFD (the files are UTF-8; gnuplot, browsers
// and JSON readers refuse or mangle anything else) and accepts any bytes, NUL included.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace buckle::scene::escape {

/// `s` with each maximal invalid UTF-8 subpart (Unicode ch. 3, "U+FFFD substitution of maximal
/// subparts") replaced by U+FFFD; valid UTF-8 is returned unchanged.
std::string validUtf8(std::string_view s);

/// The text a reader of the other formats gets back: validUtf8(s) with CR LF and a lone CR as
/// LF, and every other control character (C0 except TAB and LF, DEL) as U+FFFD.
std::string displayText(std::string_view s);

/// A gnuplot double-quoted string literal whose value is displayText(s): backslash, double
/// quote, TAB and LF escaped (\\, \", \t, \n), the backquote — command substitution even inside
/// double quotes — written as its octal escape \140. Safe anywhere gnuplot takes a string.
std::string gnuplotString(std::string_view s);

/// `s` as the text of a one-line comment (gnuplot script, .dat file; after "# "): displayText(s)
/// with TAB and LF as spaces, so the comment cannot end before the line does.
std::string commentText(std::string_view s);

/// A double-quoted field of a whitespace-separated .dat file read by gnuplot (a `with labels`
/// column). gnuplot reads such a field up to the next double quote with no escapes, so the
/// characters it cannot hold are replaced: `"` by `'`, `\` by `/`, TAB and LF by spaces.
std::string datField(std::string_view s);

/// A CSV field (RFC 4180): quoted when it holds a comma, a double quote, CR or LF (double quotes
/// doubled inside); the value read back is validUtf8(s) with NUL as U+FFFD.
std::string csvField(std::string_view s);

/// A JSON document as text (indent < 0: one line). Invalid UTF-8 inside strings is replaced by
/// U+FFFD instead of nlohmann's default of throwing, so a hostile label never loses an output.
std::string jsonText(const nlohmann::json& doc, int indent = 2);

/// jsonText for the inside of an HTML <script type="application/json"> element: every `<` as
/// \u003c (it can only occur inside a JSON string), so no "</script>" or "<!--" ends or changes
/// the element; JSON.parse of the element's textContent returns the document.
std::string jsonForHtmlScript(const nlohmann::json& doc);
/// The same for JSON already written as text (the report's large arrays are written directly).
std::string htmlScriptSafe(std::string_view jsonText);
/// htmlScriptSafe in place for the text from `from` on (the report's data written into its page).
void makeHtmlScriptSafe(std::string& text, size_t from);

}  // namespace buckle::scene::escape
