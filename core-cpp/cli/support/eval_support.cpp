#include "support/eval_support.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace pdnav::cli {

std::string fixed_or(double v, int decimals, const char* missing) {
  if (!std::isfinite(v)) return missing;
  char b[32];
  std::snprintf(b, sizeof b, "%.*f", decimals, v);
  return b;
}

double median_of_finite(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::optional<std::vector<double>> parse_number_list(const std::string& text) {
  std::vector<double> out;
  std::stringstream in(text);
  std::string part;
  while (std::getline(in, part, ',')) {
    char* end = nullptr;
    const double v = std::strtod(part.c_str(), &end);
    if (part.empty() || end != part.c_str() + part.size() || !std::isfinite(v)) return std::nullopt;
    out.push_back(v);
  }
  if (out.empty() || (!text.empty() && text.back() == ',')) return std::nullopt;  // "" or "1,2,"
  return out;
}

void add_fusion_model_option(CLI::App* c, std::string& model) {
  c->add_option("--fusion-model", model,
                "fused covariance model: issue28 (default) | issue14 (before issue 28, for before/after figures)")
      ->capture_default_str();
}

void apply_fusion_model(const std::string& model, fusion::FusionOptions& options) {
  if (model == "issue14") options = fusion::fusion_options_before_issue28();
  else if (model != "issue28") throw std::invalid_argument("--fusion-model: issue28 (default) or issue14");
}

}  // namespace pdnav::cli
