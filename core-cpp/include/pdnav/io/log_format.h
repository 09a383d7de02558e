// Facts about the session log format shared by the reader, the writer and the tools
// (docs/log-format.md): line type names, their default column lists, sample equality.
#pragma once
#include <string>
#include <string_view>
#include <vector>

#include "pdnav/geo/samples.h"

namespace pdnav::io {

/// Version written as "# Version: pdnav-log 1". Bumped only when an existing column changes
/// meaning; adding columns or line types keeps the version (readers go by column names).
inline constexpr int kLogFormatVersion = 1;

/// The line type token of a sample ("Accel", "Raw", "Fix", ...).
std::string_view line_type_name(const Sample& s);
/// Every line type, in the order of the Sample variant.
std::vector<std::string_view> line_type_names();
/// Columns the writer emits for a line type, the type token first ("Accel", "utcTimeMillis",
/// ...). Empty for an unknown type. Also the columns the reader assumes without a header.
std::vector<std::string> default_columns(std::string_view line_type);
/// Field-by-field equality as the log sees it: same line type, doubles bit-identical or both
/// NaN, integers, strings and bytes equal. writer -> reader round trips satisfy it.
bool same_sample(const Sample& a, const Sample& b);

}  // namespace pdnav::io
