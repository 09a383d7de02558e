// Helpers shared by the commands: number text for the printed tables, the median of a figure
// over walks, the --fusion-model option, and option values given as lists of numbers.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "pdnav/fusion/navigator.h"

namespace pdnav::cli {

/// v as printf "%.<decimals>f", or `missing` when v is not finite.
std::string fixed_or(double v, int decimals, const char* missing);

/// Median of the finite values; NaN when there are none.
double median_of_finite(std::vector<double> v);

/// "a,b,c": comma-separated decimal numbers, each finite, nothing else around them; nullopt when
/// any part is not one (the caller names the option and what it expected).
std::optional<std::vector<double>> parse_number_list(const std::string& text);

/// --fusion-model: the fused covariance model, "issue28" (default) or "issue14" (before issue 28).
void add_fusion_model_option(CLI::App* c, std::string& model);
/// Applies a --fusion-model name: "issue28" leaves `options` as they are, "issue14" sets
/// fusion::fusion_options_before_issue28(); std::invalid_argument for another name.
void apply_fusion_model(const std::string& model, fusion::FusionOptions& options);

}  // namespace pdnav::cli
