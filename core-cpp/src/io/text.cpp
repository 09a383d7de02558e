#include "io/text.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

#include <fast_float/fast_float.h>

namespace pdnav::io::detail {
namespace {

constexpr double kMaxExactInt = 9007199254740992.0;  // 2^53
constexpr char kHex[] = "0123456789ABCDEF";

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

/// Shortest round-trip text of a finite double in scientific form ("1.01325e+05").
std::size_t scientific_chars(double x, char* buf, std::size_t size) {
#if defined(__cpp_lib_to_chars) && __cpp_lib_to_chars >= 201611L
  const auto r = std::to_chars(buf, buf + size, x, std::chars_format::scientific);
  return static_cast<std::size_t>(r.ptr - buf);
#else
  const int n = std::snprintf(buf, size, "%.16e", x);  // 17 significant digits round-trip
  for (int i = 0; i < n; ++i)
    if (buf[i] == ',') buf[i] = '.';  // defensive: a non-C LC_NUMERIC
  return n > 0 ? static_cast<std::size_t>(n) : 0;
#endif
}

/// Splits scientific text into sign, significant digits and the decimal exponent of the
/// first digit: x = 0.d1d2d3... * 10^(exp10 + 1).
struct Decimal {
  bool negative = false;
  std::string digits;
  int exp10 = 0;
};

Decimal split_scientific(std::string_view t) {
  Decimal d;
  std::size_t i = 0;
  if (i < t.size() && t[i] == '-') { d.negative = true; ++i; }
  for (; i < t.size() && t[i] != 'e' && t[i] != 'E'; ++i)
    if (t[i] != '.') d.digits.push_back(t[i]);
  if (i < t.size()) {
    ++i;
    if (i < t.size() && t[i] == '+') ++i;
    std::from_chars(t.data() + i, t.data() + t.size(), d.exp10);
  }
  // drop trailing zeros of the significand (snprintf fallback pads them)
  while (d.digits.size() > 1 && d.digits.back() == '0') d.digits.pop_back();
  return d;
}

void append_decimal(std::string& out, const Decimal& d) {
  if (d.negative) out.push_back('-');
  const int n = static_cast<int>(d.digits.size());
  const int point = d.exp10 + 1;  // digits before the decimal point
  if (d.exp10 < -5 || d.exp10 >= 21) {
    out.push_back(d.digits[0]);
    if (n > 1) { out.push_back('.'); out.append(d.digits, 1, std::string::npos); }
    out.push_back('e');
    append_i64(out, d.exp10);
  } else if (point <= 0) {
    out.append("0.");
    out.append(static_cast<std::size_t>(-point), '0');
    out.append(d.digits);
  } else if (point >= n) {
    out.append(d.digits);
    out.append(static_cast<std::size_t>(point - n), '0');
  } else {
    out.append(d.digits, 0, static_cast<std::size_t>(point));
    out.push_back('.');
    out.append(d.digits, static_cast<std::size_t>(point), std::string::npos);
  }
}

}  // namespace

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

std::string lower_ascii(std::string_view s) {
  std::string out(s);
  for (char& c : out)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return out;
}

std::string printable(std::string_view s, std::size_t max) {
  std::string out;
  for (char c : s.substr(0, max)) {
    const auto u = static_cast<unsigned char>(c);
    out.push_back(u < 0x20 || u >= 0x7f ? '?' : c);
  }
  if (s.size() > max) out += "...";
  return out;
}

bool parse_f64(std::string_view s, double& out) {
  s = trim(s);
  if (s.empty()) return false;
  const auto r = fast_float::from_chars(s.data(), s.data() + s.size(), out);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

bool parse_i64(std::string_view s, std::int64_t& out) {
  s = trim(s);
  if (s.empty()) return false;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), out);
  if (r.ec == std::errc() && r.ptr == s.data() + s.size()) return true;
  double x = 0.0;
  if (!parse_f64(s, x) || !std::isfinite(x) || std::fabs(x) > kMaxExactInt || x != std::floor(x))
    return false;
  out = static_cast<std::int64_t>(x);
  return true;
}

bool parse_f64_pow10(std::string_view s, int pow10, double& out) {
  s = trim(s);
  double plain = 0.0;
  if (!parse_f64(s, plain)) return false;
  if (!std::isfinite(plain)) {
    out = plain;
    return true;
  }
  std::size_t e = s.find_first_of("eE");
  long exponent = 0;
  std::string_view mantissa = s;
  if (e != std::string_view::npos) {
    mantissa = s.substr(0, e);
    std::string_view et = s.substr(e + 1);
    if (!et.empty() && et.front() == '+') et.remove_prefix(1);
    const auto r = std::from_chars(et.data(), et.data() + et.size(), exponent);
    if (r.ec != std::errc()) exponent = et.front() == '-' ? -100000 : 100000;  // saturate
    if (exponent > 100000) exponent = 100000;
    if (exponent < -100000) exponent = -100000;
  }
  std::string shifted(mantissa);
  shifted.push_back('e');
  append_i64(shifted, exponent + pow10);
  return parse_f64(shifted, out);
}

bool parse_bool(std::string_view s, bool& out) {
  s = trim(s);
  auto eq = [&](std::string_view w) {
    if (s.size() != w.size()) return false;
    for (std::size_t i = 0; i < s.size(); ++i)
      if ((s[i] | 0x20) != w[i]) return false;
    return true;
  };
  if (s == "1" || eq("true")) { out = true; return true; }
  if (s == "0" || eq("false")) { out = false; return true; }
  return false;
}

void append_f64(std::string& out, double x) {
  if (std::isnan(x)) return;
  char buf[64];
#if defined(__cpp_lib_to_chars) && __cpp_lib_to_chars >= 201611L
  const auto r = std::to_chars(buf, buf + sizeof buf, x);
  out.append(buf, static_cast<std::size_t>(r.ptr - buf));
#else
  if (std::isinf(x)) { out.append(x < 0 ? "-inf" : "inf"); return; }
  out.append(buf, scientific_chars(x, buf, sizeof buf));
#endif
}

void append_f64_pow10(std::string& out, double x, int pow10) {
  if (std::isnan(x)) return;
  if (std::isinf(x)) { out.append(x < 0 ? "-inf" : "inf"); return; }
  if (x == 0.0) { out.append(std::signbit(x) ? "-0" : "0"); return; }
  char buf[64];
  Decimal d = split_scientific(std::string_view(buf, scientific_chars(x, buf, sizeof buf)));
  d.exp10 -= pow10;
  append_decimal(out, d);
}

void append_i64(std::string& out, std::int64_t x) {
  char buf[24];
  const auto r = std::to_chars(buf, buf + sizeof buf, x);
  out.append(buf, static_cast<std::size_t>(r.ptr - buf));
}

void append_escaped(std::string& out, std::string_view s) {
  for (char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '%' || c == ',' || u < 0x20 || u == 0x7f) {
      out.push_back('%');
      out.push_back(kHex[u >> 4]);
      out.push_back(kHex[u & 0xF]);
    } else {
      out.push_back(c);
    }
  }
}

bool unescape(std::string_view s, std::string& out) {
  out.clear();
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] != '%') { out.push_back(s[i]); continue; }
    if (i + 2 >= s.size()) return false;
    const int hi = hex_value(s[i + 1]);
    const int lo = hex_value(s[i + 2]);
    if (hi < 0 || lo < 0) return false;
    out.push_back(static_cast<char>(hi * 16 + lo));
    i += 2;
  }
  return true;
}

}  // namespace pdnav::io::detail
