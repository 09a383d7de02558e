// LogReader: streams a session log / GnssLogger log line by line (docs/log-format.md).
#include "pdnav/io/log_reader.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <system_error>
#include <utility>

#include "io/line_source.h"
#include "io/schema.h"
#include "io/skip_reasons.h"
#include "io/text.h"
#include "pdnav/geo/time.h"
#include "pdnav/io/log_format.h"

namespace pdnav::io {

namespace {
std::string where(const std::string& file, std::int64_t line) {
  return line > 0 ? file + ":" + std::to_string(line) : file;
}
}  // namespace

IoError::IoError(std::string file, std::int64_t line, std::string reason)
    : std::runtime_error(where(file, line) + ": " + reason),
      file_(std::move(file)), line_(line), reason_(std::move(reason)) {}

std::string LogIssue::to_string() const { return where(file, line) + ": " + reason; }

std::int64_t ReadStats::skipped_total() const {
  std::int64_t n = 0;
  for (const auto& [reason, count] : skipped_by_reason) n += count;
  return n;
}

namespace detail {
namespace {

// Skip reason categories of this format only (the shared ones: io/skip_reasons.h).
constexpr const char* kBadEscape = "bad percent escape";
constexpr const char* kNoBase = "no elapsed-time base yet";
constexpr const char* kNoTime = "no time in line";
constexpr std::size_t kMaxDistinctKeys = 64;  // bounds maps fed by file content

/// Why a line was skipped. `malformed` lines throw in strict mode; the others never do.
struct LineError {
  std::string category;
  std::string detail;
  bool malformed = true;
};

bool checked_mul(std::int64_t a, std::int64_t b, std::int64_t& out) { return !__builtin_mul_overflow(a, b, &out); }
bool checked_add(std::int64_t a, std::int64_t b, std::int64_t& out) { return !__builtin_add_overflow(a, b, &out); }
bool checked_sub(std::int64_t a, std::int64_t b, std::int64_t& out) { return !__builtin_sub_overflow(a, b, &out); }

// Old GnssLogger names (v1.x, v2) and spelling variants, lower case: alias -> canonical.
constexpr std::pair<std::string_view, std::string_view> kAliases[] = {
    {"latitude", "latitudedegrees"},   {"longitude", "longitudedegrees"},
    {"altitude", "altitudemeters"},    {"speed", "speedmps"},
    {"accuracy", "accuracymeters"},    {"bearing", "bearingdegrees"},
    {"(utc)timeinms", "unixtimemillis"}, {"(utc)timeinms", "utctimemillis"},
    {"unixtimemillis", "utctimemillis"}, {"utctimemillis", "unixtimemillis"},
    {"elapsedrealtimens", "elapsedrealtimenanos"},
    {"submessageid", "sub-messageid"}, {"data", "data(bytes)"},
};

/// Column layout of one line type: from the file's header, or the writer's default.
struct Schema {
  int n_cols = 0;               // header names including the type token
  int bytes_col = -1;           // Data(Bytes): takes every surplus field
  int elapsed_ms_col = -1;      // v1.x Raw ElapsedRealtimeMillis
  std::vector<int> slot_col;    // canonical slot -> header column, -1 when absent
};


/// Lower-case field names of line type S in writer order; an immutable table made once.
template <class S> const std::vector<std::string>& canonical_names() {
  static const std::vector<std::string> kNames = [] {
    NameCollector c;
    S s;
    visit_fields(s, c);
    for (std::string& n : c.names) n = lower_ascii(n);  // header matching is case-insensitive
    return std::move(c.names);
  }();
  return kNames;
}

/// Builds the schema of line type S from header column names (type token first).
template <class S> Schema make_schema(const std::vector<std::string>& header) {
  const std::vector<std::string>& canon = canonical_names<S>();
  Schema sc;
  sc.n_cols = static_cast<int>(header.size());
  sc.slot_col.assign(canon.size(), -1);
  for (int col = 1; col < sc.n_cols; ++col) {
    const std::string name = lower_ascii(trim(header[static_cast<std::size_t>(col)]));
    if (name == "elapsedrealtimemillis") { sc.elapsed_ms_col = col; continue; }
    auto slot_of = [&](std::string_view n) {
      auto it = std::find(canon.begin(), canon.end(), n);
      return it == canon.end() ? -1 : static_cast<int>(it - canon.begin());
    };
    int slot = slot_of(name);
    for (const auto& [alias, target] : kAliases)
      if (slot < 0 && alias == name) slot = slot_of(target);
    if (slot < 0 || sc.slot_col[static_cast<std::size_t>(slot)] >= 0) continue;  // unknown / dup
    sc.slot_col[static_cast<std::size_t>(slot)] = col;
    if (canon[static_cast<std::size_t>(slot)] == "data(bytes)") sc.bytes_col = col;
  }
  return sc;
}

template <class S> Schema default_schema() {
  std::vector<std::string> header{std::string(LineTraits<S>::name)};
  for (const std::string& n : canonical_names<S>()) header.push_back(n);
  return make_schema<S>(header);
}

/// Time columns seen while parsing a line (before it is placed on the timeline).
struct LineTimes {
  std::optional<TimeNs> elapsed_ns;
  std::optional<std::int64_t> elapsed_ms;
};

/// Fills a sample from the fields of one line through its schema.
class FieldReader {
 public:
  FieldReader(const Schema& sc, const std::vector<std::string_view>& fields)
      : sc_(sc), fields_(fields) {
    data_count_ = static_cast<int>(fields.size()) - (sc.n_cols - 1);
  }
  LineTimes times;

  std::string_view column(int col) const {
    if (col < 0) return {};
    if (sc_.bytes_col >= 0 && col > sc_.bytes_col) col += data_count_ - 1;
    return fields_[static_cast<std::size_t>(col)];
  }

  void elapsed(std::string_view name, TimeNs&) {
    const std::string_view f = trim(next());
    if (f.empty()) return;
    std::int64_t v = 0;
    if (!parse_i64(f, v)) fail(kInvalidTime, name, f, "is not an integer time");
    times.elapsed_ns = v;
  }
  void i64(std::string_view name, std::int64_t& x) {
    const std::string_view f = trim(next());
    if (f.empty()) { x = kMissingInt; return; }
    if (!parse_i64(f, x)) fail(kNonNumeric, name, f, "is not an integer");
  }
  void i32(std::string_view name, int& x) {
    const std::string_view f = trim(next());
    if (f.empty()) { x = 0; return; }
    std::int64_t v = 0;
    if (!parse_i64(f, v)) fail(kNonNumeric, name, f, "is not an integer");
    if (v < INT32_MIN || v > INT32_MAX) fail(kOutOfRange, name, f, "does not fit 32 bits");
    x = static_cast<int>(v);
  }
  void f64(std::string_view name, double& x) {
    const std::string_view f = trim(next());
    if (f.empty()) { x = kNaN; return; }
    if (!parse_f64(f, x)) fail(kNonNumeric, name, f, "is not a number");
  }
  void hpa(std::string_view name, double& pa) {
    const std::string_view f = trim(next());
    if (f.empty()) { pa = kNaN; return; }
    if (!parse_f64_pow10(f, 2, pa)) fail(kNonNumeric, name, f, "is not a number");
  }
  void flag(std::string_view name, bool& x) {
    const std::string_view f = trim(next());
    if (f.empty()) { x = false; return; }
    if (!parse_bool(f, x)) fail(kNonNumeric, name, f, "is not 0/1/true/false");
  }
  void text(std::string_view name, std::string& x) {
    const std::string_view f = next();
    if (!unescape(f, x)) fail(kBadEscape, name, f, "has a '%' not followed by two hex digits");
  }
  void bytes(std::string_view name, std::vector<std::uint8_t>& x) {
    ++slot_;
    x.clear();
    if (sc_.bytes_col < 0) return;
    for (int i = 0; i < data_count_; ++i) {
      const std::string_view f = trim(fields_[static_cast<std::size_t>(sc_.bytes_col + i)]);
      std::int64_t v = 0;
      if (!parse_i64(f, v)) fail(kNonNumeric, name, f, "is not a byte");
      if (v < -128 || v > 255) fail(kOutOfRange, name, f, "is not in -128..255");
      x.push_back(static_cast<std::uint8_t>(v & 0xFF));
    }
  }

 private:
  std::string_view next() { return column(sc_.slot_col[static_cast<std::size_t>(slot_++)]); }
  [[noreturn]] static void fail(const char* category, std::string_view name, std::string_view f,
                                const char* what) {
    throw LineError{category, std::string(name) + " '" + printable(f) + "' " + what};
  }

  const Schema& sc_;
  const std::vector<std::string_view>& fields_;
  int data_count_ = 0;
  std::size_t slot_ = 0;
};

/// UTC (ns since the Unix epoch) of a Raw line from its GnssClock:
/// GPS time = TimeNanos - (FullBiasNanos + BiasNanos), UTC = GPS - leap seconds (geo/time.h).
std::optional<std::int64_t> raw_clock_utc_ns(const GnssRawSample& r) {
  if (r.time_nanos == kMissingInt || r.full_bias_nanos == kMissingInt || r.full_bias_nanos == 0)
    return std::nullopt;
  std::int64_t gps_ns = 0;
  if (!checked_sub(r.time_nanos, r.full_bias_nanos, gps_ns)) return std::nullopt;
  const double bias = std::isfinite(r.bias_nanos) ? r.bias_nanos : 0.0;
  constexpr std::int64_t kMaxGpsNs = std::int64_t{1} << 62;
  if (std::fabs(bias) > 1e9 || gps_ns <= 0 || gps_ns > kMaxGpsNs) return std::nullopt;
  gps_ns -= std::llround(bias);
  if (gps_ns <= 0) return std::nullopt;
  const int leap = geo::leap_seconds_at_gps_ns(gps_ns);
  return gps_ns + geo::kGpsEpochUnixMs * kNsPerMs - std::int64_t{leap} * kNsPerS;
}

std::optional<std::int64_t> ms_to_ns(std::int64_t ms) {
  std::int64_t ns = 0;
  if (ms == kMissingInt || !checked_mul(ms, kNsPerMs, ns)) return std::nullopt;
  return ns;
}

}  // namespace

/// The reader's state and logic, independent of the pimpl wrapper.
class ReaderCore {
 public:
  ReaderCore(std::istream& in, std::string name, LogReaderOptions opt, std::uint64_t size_bytes)
      : source_(in), name_(std::move(name)), opt_(opt), size_bytes_(size_bytes) {
    install_default_schemas(std::make_index_sequence<kNumLineTypes>{});
    last_t_.fill(std::numeric_limits<TimeNs>::min());
  }

  bool next(Sample& out);
  ReadStats& stats() {
    stats_.samples_by_type.clear();
    for (std::size_t i = 0; i < kNumLineTypes; ++i)
      if (counts_[i] > 0) stats_.samples_by_type[std::string(type_names_[i])] = counts_[i];
    return stats_;
  }
  const std::map<std::string, std::string>& header_info() const { return header_info_; }
  double progress() const {
    if (size_bytes_ == 0) return 0.0;
    return std::min(1.0, static_cast<double>(source_.bytes_consumed()) / static_cast<double>(size_bytes_));
  }
  const std::string& name() const { return name_; }

  // Used by the per-type parse functions.
  template <std::size_t I> void parse_as(Sample& out);

 private:
  template <std::size_t... I> void install_default_schemas(std::index_sequence<I...>) {
    // built once per process (immutable afterwards), copied into each reader
    static const std::array<Schema, kNumLineTypes> kDefaults{
        default_schema<std::variant_alternative_t<I, Sample>>()...};
    schemas_ = kDefaults;
    ((type_names_[I] = LineTraits<std::variant_alternative_t<I, Sample>>::name), ...);
  }
  template <std::size_t... I> void set_schema(std::size_t type, const std::vector<std::string>& h,
                                              std::index_sequence<I...>) {
    ((I == type ? (schemas_[I] = make_schema<std::variant_alternative_t<I, Sample>>(h), 0) : 0), ...);
  }
  int type_index(std::string_view token) const {
    for (std::size_t i = 0; i < kNumLineTypes; ++i)
      if (type_names_[i] == token) return static_cast<int>(i);
    return -1;
  }
  void header_line(std::string_view text);
  void info_line(std::string_view text);
  bool data_line(std::string_view text, Sample& out);
  void skip(const LineError& e);
  std::string unknown_type_reason(std::string_view token);
  template <class S> bool place(S& s, const LineTimes& lt);
  template <class S> std::optional<TimeNs> direct_time(const S& s, const LineTimes& lt);
  template <class S> void learn_offset(const S& s, TimeNs t);
  void check_order(std::size_t type, const Sample& s, TimeNs t);

  LineSource source_;
  std::string name_;
  LogReaderOptions opt_;
  std::uint64_t size_bytes_;
  std::int64_t line_no_ = 0;
  bool empty_reported_ = false;
  std::array<Schema, kNumLineTypes> schemas_;
  std::array<std::string_view, kNumLineTypes> type_names_;
  std::array<std::int64_t, kNumLineTypes> counts_{};
  std::array<TimeNs, kNumLineTypes> last_t_{};
  std::map<std::string, TimeNs> last_fix_t_;   // per Fix provider (bounded)
  std::vector<std::string_view> fields_;
  std::optional<std::int64_t> wall_offset_ns_, gnss_offset_ns_;  // elapsed - UTC
  std::optional<TimeNs> latest_t_;
  ReadStats stats_;
  std::map<std::string, std::string> header_info_;
  std::size_t unknown_types_ = 0;
};

void ReaderCore::skip(const LineError& e) {
  if (e.malformed && opt_.strict) throw IoError(name_, line_no_, e.category + ": " + e.detail);
  ++stats_.skipped_by_reason[e.category];
  if (stats_.issues.size() < opt_.max_reported_issues)
    stats_.issues.push_back(LogIssue{name_, line_no_, e.category + (e.detail.empty() ? "" : ": " + e.detail)});
}

std::string ReaderCore::unknown_type_reason(std::string_view token) {
  std::string reason = "unknown line type '" + printable(token, 24) + "'";
  if (stats_.skipped_by_reason.count(reason) > 0) return reason;
  if (unknown_types_ >= kMaxDistinctKeys) return "unknown line type (more names)";
  ++unknown_types_;
  return reason;
}

void ReaderCore::info_line(std::string_view text) {
  // "Key: value Key2: value two" -> pairs; a token ending in ':' starts a key.
  std::string key, value;
  auto flush = [&] {
    while (!value.empty() && (value.back() == ',' || value.back() == ' ')) value.pop_back();
    if (!key.empty() && (header_info_.size() < kMaxDistinctKeys || header_info_.count(key)))
      header_info_[key] = value.substr(0, 256);
  };
  std::size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && text[i] == ' ') ++i;
    std::size_t j = i;
    while (j < text.size() && text[j] != ' ') ++j;
    const std::string_view tok = text.substr(i, j - i);
    if (tok.size() > 1 && tok.back() == ':') {
      flush();
      key = printable(tok.substr(0, tok.size() - 1), 64);
      value.clear();
    } else if (!tok.empty()) {
      if (!value.empty()) value.push_back(' ');
      value += printable(tok, 256);
    }
    i = j;
  }
  flush();
}

void ReaderCore::header_line(std::string_view text) {
  text = trim(text.substr(1));
  if (text.empty()) return;
  const std::size_t comma = text.find(',');
  const std::size_t first_space = text.find(' ');
  const std::string_view first = text.substr(0, std::min(comma, first_space));
  if (!first.empty() && first.back() == ':') { info_line(text); return; }
  if (comma == std::string_view::npos || first_space < comma) return;  // free comment
  const int type = type_index(first);
  if (type < 0) return;
  std::vector<std::string> header;
  std::size_t start = 0;
  for (;;) {
    const std::size_t c = text.find(',', start);
    header.emplace_back(trim(text.substr(start, c == std::string_view::npos ? std::string_view::npos : c - start)));
    if (c == std::string_view::npos) break;
    start = c + 1;
  }
  set_schema(static_cast<std::size_t>(type), header, std::make_index_sequence<kNumLineTypes>{});
}

template <class S> std::optional<TimeNs> ReaderCore::direct_time(const S& s, const LineTimes& lt) {
  if (lt.elapsed_ns) return lt.elapsed_ns;
  if constexpr (std::is_same_v<S, GnssRawSample>) {
    if (lt.elapsed_ms) {
      const auto ns = ms_to_ns(*lt.elapsed_ms);
      if (!ns) throw LineError{kInvalidTime, "ElapsedRealtimeMillis out of range"};
      return ns;
    }
    if (s.chipset_elapsed_realtime_nanos != kMissingInt) return s.chipset_elapsed_realtime_nanos;
  }
  return std::nullopt;
}

/// UTC (ns) of a line, if it has one.
template <class S> std::optional<std::int64_t> line_utc_ns(const S& s) {
  if constexpr (std::is_same_v<S, GnssRawSample>) {
    if (auto clock = raw_clock_utc_ns(s)) return clock;
  }
  if constexpr (LineTraits<S>::utc != UtcKind::kNone) return ms_to_ns(s.utc_ms);
  return std::nullopt;
}

/// Puts a line on the elapsed timeline (docs/log-format.md, "Time"); true when the line
/// carried its elapsed time itself (only then may it teach a UTC<->elapsed offset).
template <class S> bool ReaderCore::place(S& s, const LineTimes& lt) {
  if (auto t = direct_time(s, lt)) { s.t_ns = *t; return true; }
  if constexpr (LineTraits<S>::utc != UtcKind::kNone) {
    if (auto utc = line_utc_ns(s)) {
      const bool gnss = LineTraits<S>::utc == UtcKind::kGnss;
      const auto& first = gnss ? gnss_offset_ns_ : wall_offset_ns_;
      const auto& second = gnss ? wall_offset_ns_ : gnss_offset_ns_;
      const auto& off = first ? first : second;
      if (!off) throw LineError{kNoBase, "UTC time but no UTC<->elapsed offset learned yet", false};
      if (!checked_add(*utc, *off, s.t_ns)) throw LineError{kInvalidTime, "mapped time out of range"};
      return false;
    }
  }
  if constexpr (std::is_same_v<S, NavMessageSample> || std::is_same_v<S, MetaSample>) {
    if (!latest_t_) throw LineError{kNoBase, "no earlier sample to take the time from", false};
    s.t_ns = *latest_t_;
    return false;
  }
  throw LineError{kNoTime, "neither an elapsed time nor a usable UTC time"};
}

template <class S> void ReaderCore::learn_offset(const S& s, TimeNs t) {
  if constexpr (std::is_same_v<S, GnssRawSample> || LineTraits<S>::learns_wall_offset) {
    const auto utc = line_utc_ns(s);
    std::int64_t off = 0;
    if (!utc || !checked_sub(t, *utc, off)) return;
    if constexpr (std::is_same_v<S, GnssRawSample>) gnss_offset_ns_ = off;
    else wall_offset_ns_ = off;
  }
}

void ReaderCore::check_order(std::size_t type, const Sample& s, TimeNs t) {
  TimeNs* last = &last_t_[type];
  if (const auto* fix = std::get_if<FixSample>(&s)) {  // each provider is its own stream
    auto it = last_fix_t_.find(fix->provider);
    if (it == last_fix_t_.end()) {
      if (last_fix_t_.size() >= kMaxDistinctKeys) return;
      it = last_fix_t_.emplace(fix->provider, std::numeric_limits<TimeNs>::min()).first;
    }
    last = &it->second;
  }
  if (opt_.drop_backwards_time && t < *last)
    throw LineError{kBackwards, "t=" + std::to_string(t) + " ns < previous " +
                                    std::string(type_names_[type]) + " t=" + std::to_string(*last) + " ns"};
  *last = t;
}

template <std::size_t I> void ReaderCore::parse_as(Sample& out) {
  using S = std::variant_alternative_t<I, Sample>;
  const Schema& sc = schemas_[I];
  const auto n = static_cast<int>(fields_.size());
  if (sc.bytes_col >= 0 ? n < sc.n_cols - 1 : n != sc.n_cols)
    throw LineError{kWrongFieldCount, std::string(type_names_[I]) + " has " + std::to_string(n) +
                                          " fields, header has " + std::to_string(sc.n_cols)};
  S& s = out.template emplace<I>();
  FieldReader reader(sc, fields_);
  visit_fields(s, reader);
  if constexpr (std::is_same_v<S, GnssRawSample>) {
    std::int64_t ms = 0;
    const std::string_view f = trim(reader.column(sc.elapsed_ms_col));
    if (!f.empty()) {
      if (!parse_i64(f, ms)) throw LineError{kInvalidTime, "ElapsedRealtimeMillis '" + printable(f) + "' is not an integer"};
      reader.times.elapsed_ms = ms;
    }
  }
  if constexpr (std::is_same_v<S, SensorAccuracySample>) {
    if (s.accuracy < -1 || s.accuracy > 3)
      throw LineError{kOutOfRange, "Accuracy " + std::to_string(s.accuracy) + " is not a SENSOR_STATUS (-1..3)"};
    if (s.sensor_type <= 0)
      throw LineError{kOutOfRange, "SensorType " + std::to_string(s.sensor_type) + " is not an Android sensor type (> 0)"};
  }
  const bool direct = place(s, reader.times);
  check_order(I, out, s.t_ns);
  if (direct) learn_offset(s, s.t_ns);
  latest_t_ = latest_t_ ? std::max(*latest_t_, s.t_ns) : s.t_ns;
  ++counts_[I];
}

namespace {
using ParseFn = void (ReaderCore::*)(Sample&);
template <std::size_t... I> constexpr std::array<ParseFn, kNumLineTypes> parse_table(std::index_sequence<I...>) {
  return {&ReaderCore::parse_as<I>...};
}
}  // namespace

bool ReaderCore::data_line(std::string_view text, Sample& out) {
  if (fields_.capacity() > 65536) std::vector<std::string_view>().swap(fields_);  // after a huge line
  fields_.clear();
  std::size_t start = 0;
  for (;;) {
    const void* c = std::memchr(text.data() + start, ',', text.size() - start);
    if (c == nullptr) { fields_.push_back(text.substr(start)); break; }
    const auto pos = static_cast<std::size_t>(static_cast<const char*>(c) - text.data());
    fields_.push_back(text.substr(start, pos - start));
    start = pos + 1;
  }
  const std::string_view token = trim(fields_[0]);
  const int type = type_index(token);
  if (type < 0) throw LineError{unknown_type_reason(token), "", false};
  static constexpr auto kTable = parse_table(std::make_index_sequence<kNumLineTypes>{});
  (this->*kTable[static_cast<std::size_t>(type)])(out);
  return true;
}

bool ReaderCore::next(Sample& out) {
  Line line;
  while (source_.next(line)) {
    ++line_no_;
    ++stats_.lines;
    const std::string_view text = trim(line.text);
    try {
      if (line.too_long) throw LineError{kTooLong, "longer than " + std::to_string(LineSource::kMaxLineBytes) + " bytes"};
      if (!line.terminated) {
        if (!text.empty()) throw LineError{kTorn, "no newline at end of input (" + std::to_string(text.size()) + " bytes)"};
        continue;
      }
      if (text.empty()) continue;
      if (text.front() == '#') { header_line(text); continue; }
      if (data_line(line.text, out)) { ++stats_.samples; return true; }
    } catch (const LineError& e) {
      skip(e);
    }
  }
  if (source_.read_error()) throw IoError(name_, line_no_, "read error");
  if (source_.bytes_consumed() == 0 && !empty_reported_) {
    empty_reported_ = true;
    throw IoError(name_, 0, "empty log (0 bytes)");
  }
  return false;
}

}  // namespace detail

struct LogReader::Impl {
  std::unique_ptr<std::istream> in;
  std::unique_ptr<detail::ReaderCore> core;
};

namespace {
std::uint64_t checked_file_size(const std::string& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) throw IoError(path, 0, "cannot open: no such file");
  if (std::filesystem::is_directory(status)) throw IoError(path, 0, "cannot open: is a directory");
  const auto size = std::filesystem::file_size(path, ec);
  return ec ? 0 : static_cast<std::uint64_t>(size);
}
}  // namespace

LogReader::LogReader(const std::string& path, LogReaderOptions opt) : impl_(std::make_unique<Impl>()) {
  const std::uint64_t size = checked_file_size(path);
  auto file = std::make_unique<std::ifstream>(path, std::ios::binary);
  if (!*file) throw IoError(path, 0, std::string("cannot open: ") + std::strerror(errno));
  impl_->in = std::move(file);
  impl_->core = std::make_unique<detail::ReaderCore>(*impl_->in, path, opt, size);
}

LogReader::LogReader(std::unique_ptr<std::istream> in, std::string name, LogReaderOptions opt)
    : impl_(std::make_unique<Impl>()) {
  if (!in) throw IoError(name, 0, "null stream");
  impl_->in = std::move(in);
  impl_->core = std::make_unique<detail::ReaderCore>(*impl_->in, std::move(name), opt, 0);
}

LogReader::~LogReader() = default;
LogReader::LogReader(LogReader&&) noexcept = default;
LogReader& LogReader::operator=(LogReader&&) noexcept = default;

bool LogReader::next(Sample& out) { return impl_->core->next(out); }
const ReadStats& LogReader::stats() const { return impl_->core->stats(); }
const std::map<std::string, std::string>& LogReader::header_info() const { return impl_->core->header_info(); }
double LogReader::progress() const { return impl_->core->progress(); }
const std::string& LogReader::name() const { return impl_->core->name(); }

}  // namespace pdnav::io
