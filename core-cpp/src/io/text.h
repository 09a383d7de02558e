// Locale-free number parsing/formatting and field escaping for the session log format
// (docs/log-format.md). Parsing uses std::from_chars (integers) and fast_float (doubles);
// formatting uses the shortest round-trip representation, so text -> value -> text is exact.
#pragma once
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace pdnav::io::detail {

/// Strips spaces and tabs at both ends.
std::string_view trim(std::string_view s);
/// ASCII letters to lower case; other bytes unchanged.
std::string lower_ascii(std::string_view s);
/// Printable, bounded excerpt of file content for messages: control and non-ASCII bytes as
/// '?', at most `max` bytes, "..." when cut.
std::string printable(std::string_view s, std::size_t max = 40);

/// Parses a whole field as int64. Accepts an optional '-' and digits; as a fallback a
/// decimal with zero fraction whose magnitude is <= 2^53 (e.g. "129.0"). False otherwise.
bool parse_i64(std::string_view s, std::int64_t& out);
/// Parses a whole field as double (fast_float: decimal, exponent, "NaN", "Infinity").
bool parse_f64(std::string_view s, double& out);
/// Parses a decimal field and multiplies it by 10^pow10 exactly (one rounding), by shifting
/// the decimal exponent in the text. Used for hPa -> Pa so the writer's text reads back
/// bit-for-bit.
bool parse_f64_pow10(std::string_view s, int pow10, double& out);
/// Parses "1"/"0"/"true"/"false" (any case).
bool parse_bool(std::string_view s, bool& out);

/// Appends the shortest text that parses back to exactly x ("inf", "-inf"; NaN -> nothing).
void append_f64(std::string& out, double x);
/// Appends x / 10^pow10 as decimal text such that parse_f64_pow10(text, pow10) == x exactly.
void append_f64_pow10(std::string& out, double x, int pow10);
void append_i64(std::string& out, std::int64_t x);

/// Percent-escapes '%', ',', CR, LF and other control bytes (as %XX, upper-case hex).
void append_escaped(std::string& out, std::string_view s);
/// Reverses append_escaped. False on a malformed escape ("%" not followed by two hex digits).
bool unescape(std::string_view s, std::string& out);

}  // namespace pdnav::io::detail
