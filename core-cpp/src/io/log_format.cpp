#include "pdnav/io/log_format.h"

#include <cmath>
#include <cstring>
#include <variant>

#include "io/schema.h"

namespace pdnav::io {
namespace {


/// Flattens a sample into comparable values (NaN canonicalised).
struct Flattener {
  std::vector<std::uint64_t> nums;
  std::vector<std::string> strs;
  void push_f(double x) {
    if (std::isnan(x)) x = kNaN;
    std::uint64_t u = 0;
    std::memcpy(&u, &x, sizeof u);
    nums.push_back(u);
  }
  void elapsed(std::string_view, TimeNs& x) { nums.push_back(static_cast<std::uint64_t>(x)); }
  void i64(std::string_view, std::int64_t& x) { nums.push_back(static_cast<std::uint64_t>(x)); }
  void i32(std::string_view, int& x) { nums.push_back(static_cast<std::uint64_t>(x)); }
  void f64(std::string_view, double& x) { push_f(x); }
  void hpa(std::string_view, double& x) { push_f(x); }
  void flag(std::string_view, bool& x) { nums.push_back(x ? 1 : 0); }
  void text(std::string_view, std::string& x) { strs.push_back(x); }
  void bytes(std::string_view, std::vector<std::uint8_t>& x) { strs.emplace_back(x.begin(), x.end()); }
};

template <class S> Flattener flatten(const S& s) {
  Flattener f;
  S copy = s;
  detail::visit_fields(copy, f);
  return f;
}

template <std::size_t I> void add_name(std::vector<std::string_view>& out) {
  out.push_back(detail::LineTraits<std::variant_alternative_t<I, Sample>>::name);
}

template <std::size_t... I>
std::vector<std::string_view> all_names(std::index_sequence<I...>) {
  std::vector<std::string_view> out;
  (add_name<I>(out), ...);
  return out;
}

template <std::size_t I> bool columns_if(std::string_view type, std::vector<std::string>& out) {
  using S = std::variant_alternative_t<I, Sample>;
  if (detail::LineTraits<S>::name != type) return false;
  detail::NameCollector c;
  c.names.emplace_back(type);
  S s;
  detail::visit_fields(s, c);
  out = std::move(c.names);
  return true;
}

template <std::size_t... I>
std::vector<std::string> columns_of(std::string_view type, std::index_sequence<I...>) {
  std::vector<std::string> out;
  (columns_if<I>(type, out) || ...);
  return out;
}

}  // namespace

std::string_view line_type_name(const Sample& s) {
  return std::visit([](const auto& x) { return detail::LineTraits<std::decay_t<decltype(x)>>::name; }, s);
}

std::vector<std::string_view> line_type_names() {
  return all_names(std::make_index_sequence<detail::kNumLineTypes>{});
}

std::vector<std::string> default_columns(std::string_view line_type) {
  return columns_of(line_type, std::make_index_sequence<detail::kNumLineTypes>{});
}

bool same_sample(const Sample& a, const Sample& b) {
  if (a.index() != b.index()) return false;
  return std::visit(
      [&](const auto& x) {
        using S = std::decay_t<decltype(x)>;
        const Flattener fa = flatten(x);
        const Flattener fb = flatten(std::get<S>(b));
        return fa.nums == fb.nums && fa.strs == fb.strs;
      },
      a);
}

}  // namespace pdnav::io
