// open_sample_source: format detection from content and the LogReader adapter.
#include "pdnav/io/sample_source.h"

#include <algorithm>
#include <array>
#include <deque>
#include <limits>
#include <map>
#include <utility>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "io/container.h"
#include "io/readers.h"
#include "io/table_source.h"
#include "io/text.h"
#include "pdnav/io/log_format.h"

namespace pdnav::io {

namespace {

struct FormatName {
  Format f;
  std::string_view name;
};
constexpr std::array<FormatName, 6> kNames{{{Format::kAuto, "auto"},
                                            {Format::kSession, "session"},
                                            {Format::kGnssLogger, "gnsslogger"},
                                            {Format::kSensorLogger, "sensorlogger"},
                                            {Format::kPhyphox, "phyphox"},
                                            {Format::kGetSensorData, "getsensordata"}}};

constexpr const char* kExpected =
    "expected a pdnav session log or GnssLogger log (text, lines 'Type,...'), a Sensor Logger or "
    "phyphox CSV export (folder or zip), a Sensor Logger JSON export, or a GetSensorData log (text, lines 'ACCE;...')";

/// The LogReader as a SampleSource; a log that yields no sample is an error.
class LogSource : public SampleSource {
 public:
  LogSource(LogReader r, Format f, bool require) : r_(std::move(r)), f_(f), require_(require) {}
  bool next(Sample& out) override {
    if (r_.next(out)) return true;
    if (require_ && !finished_ && r_.stats().samples == 0) {
      finished_ = true;
      const ReadStats& st = r_.stats();
      std::string why = std::to_string(st.lines) + " lines, " + std::to_string(st.skipped_total()) + " skipped";
      if (!st.issues.empty()) why += " (first: " + st.issues.front().to_string() + ")";
      throw IoError(r_.name(), 0, "no samples: " + why);
    }
    finished_ = true;
    return false;
  }
  const ReadStats& stats() const override { return r_.stats(); }
  double progress() const override { return r_.progress(); }
  const std::string& name() const override { return r_.name(); }
  const std::map<std::string, std::string>& header_info() const override { return r_.header_info(); }
  Format format() const override { return f_; }

 private:
  LogReader r_;
  Format f_;
  bool require_;
  bool finished_ = false;
};

/// Android hands each sensor's FIFO over in turn (batching: SensorManager's maxReportLatency, a
/// phone's sensor hub), so a log written in arrival order (GnssLogger, GetSensorData) can hold a
/// gyroscope sample seconds after the accelerometer samples of its time; every consumer reads
/// the stream as time-ordered (the PDR pairs the gyroscope's attitude and the rotation vector
/// with each accelerometer sample: the ILC walks with the gyroscope, magnetometer and rotation
/// vector written 0.1 / 0.3 / 1 s late went 2.43 -> 2.49 / 2.70 / 3.06 m). The motion-sensor
/// samples pass through a buffer as wide as the largest lateness seen so far (at most
/// kMaxReorderS; later than that, as they come) and leave it in time order; every other sample
/// (GNSS, fixes, truth, meta: clocks that may differ) keeps its place in the motion timeline as
/// it came (after the motion samples up to the newest one read before it). A log in time order
/// passes through unchanged.
class MotionInTimeOrder : public SampleSource {
 public:
  static constexpr double kMaxReorderS = 5.0;
  explicit MotionInTimeOrder(std::unique_ptr<SampleSource> inner) : inner_(std::move(inner)), stats_(inner_->stats()) {}
  bool next(Sample& out) override {
    while (ready_.empty()) {
      Sample s;
      if (!inner_->next(s)) {
        release(std::numeric_limits<TimeNs>::max());
        if (ready_.empty()) return false;
        break;
      }
      // In order so far (no lateness seen, nothing held) and not late itself: it would enter the
      // buffer and leave it at once, so it goes out directly (every sample of a time-ordered log)
      const bool motion = is_motion(s);
      if (buf_.empty() && window_ == 0 && (!motion || !have_newest_ || sample_time_ns(s) >= newest_)) {
        if (motion) newest_ = sample_time_ns(s), have_newest_ = true;
        next_seq_out_ = ++seq_;
        out = std::move(s);
        return true;
      }
      if (!motion) {  // stays where it came in the motion timeline (its clock may differ)
        buf_.emplace(std::make_pair(have_newest_ ? newest_ : std::numeric_limits<TimeNs>::min(), seq_++), std::move(s));
        release(have_newest_ ? horizon() : std::numeric_limits<TimeNs>::max());
        continue;
      }
      const TimeNs t = sample_time_ns(s);
      // (in double first: a malformed time must not overflow the difference)
      if (have_newest_ && t < newest_ && (static_cast<double>(newest_) - static_cast<double>(t)) * 1e-9 <= kMaxReorderS)
        window_ = std::max(window_, newest_ - t);
      if (!have_newest_ || t > newest_) newest_ = t, have_newest_ = true;
      buf_.emplace(std::make_pair(t, seq_++), std::move(s));
      release(horizon());
    }
    out = std::move(ready_.front());
    ready_.pop_front();
    return true;
  }
  const ReadStats& stats() const override {
    stats_ = inner_->stats();
    stats_.reordered = reordered_;
    stats_.reorder_window_s = ns_to_s(window_);
    return stats_;
  }
  double progress() const override { return inner_->progress(); }
  const std::string& name() const override { return inner_->name(); }
  const std::map<std::string, std::string>& header_info() const override { return inner_->header_info(); }
  Format format() const override { return inner_->format(); }

 private:
  static bool is_motion(const Sample& s) {
    return std::holds_alternative<AccelSample>(s) || std::holds_alternative<GyroSample>(s) ||
           std::holds_alternative<MagSample>(s) || std::holds_alternative<UncalAccelSample>(s) ||
           std::holds_alternative<UncalGyroSample>(s) || std::holds_alternative<UncalMagSample>(s) ||
           std::holds_alternative<RotationVectorSample>(s) || std::holds_alternative<GameRotationVectorSample>(s) ||
           std::holds_alternative<StepDetectorSample>(s) || std::holds_alternative<PressureSample>(s);
  }
  /// The time up to which the buffer is complete: newest - window (saturating).
  TimeNs horizon() const {
    return newest_ < std::numeric_limits<TimeNs>::min() + window_ ? std::numeric_limits<TimeNs>::min() : newest_ - window_;
  }
  /// Every buffered sample at or before t, in time order (file order among equal times).
  void release(TimeNs t) {
    while (!buf_.empty() && buf_.begin()->first.first <= t) {
      if (buf_.begin()->first.second != next_seq_out_) ++reordered_;  // left the buffer out of file order
      next_seq_out_ = std::max(next_seq_out_, buf_.begin()->first.second + 1);
      ready_.push_back(std::move(buf_.begin()->second));
      buf_.erase(buf_.begin());
    }
  }
  std::unique_ptr<SampleSource> inner_;
  mutable ReadStats stats_;
  std::map<std::pair<TimeNs, std::int64_t>, Sample> buf_;  // (time, file order) -> sample
  std::deque<Sample> ready_;
  TimeNs newest_ = 0, window_ = 0;
  bool have_newest_ = false;
  std::int64_t seq_ = 0, next_seq_out_ = 0, reordered_ = 0;
};

std::unique_ptr<SampleSource> in_time_order(std::unique_ptr<SampleSource> s) {
  return std::make_unique<MotionInTimeOrder>(std::move(s));
}

/// GetSensorData line-type tokens (IPIN competition logfile description).
bool is_gsd_token(std::string_view t) {
  static constexpr std::string_view kTokens[] = {"ACCE", "GYRO", "MAGN", "PRES", "AHRS", "GNSS", "POSI", "WIFI",
                                                 "BLUE", "LIGH", "SOUN", "PROX", "HUMI", "TEMP", "RFID", "IMUX",
                                                 "IMUL", "IMUI", "ACC1", "GYR1", "MAG1"};
  return std::find(std::begin(kTokens), std::end(kTokens), t) != std::end(kTokens);
}

/// What a text file looks like, from its first bytes.
Format sniff_text(const std::string& head, std::string& found) {
  std::istringstream in(head);
  std::string line;
  int seen = 0, log_lines = 0, gsd_lines = 0, other = 0;
  bool session = false, gnsslogger = false;
  std::string first;
  const auto types = line_type_names();
  while (std::getline(in, line) && seen < 200) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::string_view t = detail::trim(line);
    if (t.empty()) continue;
    if (first.empty()) first = std::string(t);
    ++seen;
    if (seen == 1) {
      if (detail::is_sensorlogger_header(std::string(t))) return Format::kSensorLogger;
      if (detail::is_phyphox_header(std::string(t))) return Format::kPhyphox;
    }
    if (t.front() == '#') {
      if (t.find("pdnav-log") != std::string_view::npos) session = true;
      if (t.find("GnssLogger") != std::string_view::npos || t.find("Version: v") != std::string_view::npos) gnsslogger = true;
      const std::string_view body = detail::trim(t.substr(1));
      const std::string_view tok = body.substr(0, std::min(body.find(','), body.size()));
      if (std::find(types.begin(), types.end(), tok) != types.end()) ++log_lines;
      continue;
    }
    if (t.front() == '%') {  // GetSensorData comment header (alone it proves nothing: LaTeX, MATLAB ...)
      if (t.find("GetSensorData") != std::string_view::npos || t.find("LogFile") != std::string_view::npos) ++gsd_lines;
      continue;
    }
    const std::string_view tok = t.substr(0, std::min(t.find_first_of(",;"), t.size()));
    if (t.size() > tok.size() && t[tok.size()] == ';' && is_gsd_token(tok)) ++gsd_lines;
    else if (t.size() > tok.size() && t[tok.size()] == ',' && std::find(types.begin(), types.end(), tok) != types.end()) ++log_lines;
    else ++other;
  }
  if (log_lines > 0 && log_lines >= gsd_lines) return session || !gnsslogger ? Format::kSession : Format::kGnssLogger;
  if (gsd_lines > 0) return Format::kGetSensorData;
  found = first.empty() ? "no text lines" : "first line '" + detail::printable(first, 60) + "'";
  if (first.find("RINEX VERSION") != std::string::npos || first.find("OBSERVATION DATA") != std::string::npos ||
      first.find("NAVIGATION DATA") != std::string::npos || first.find("NAV DATA") != std::string::npos)
    found += first.find("OBSERVATION") != std::string::npos
                 ? " (a RINEX observation file: `pdnav gnss` reads it, with --nav)"
                 : " (a RINEX navigation file: give it with --nav)";
  else if (first.size() >= 3 && first[0] == '#' && (first[1] == 'c' || first[1] == 'd') && (first[2] == 'P' || first[2] == 'V'))
    found += " (an SP3 precise orbit file: `pdnav gnss` and `pdnav orbits` take it with --sp3)";
  else if (first.rfind("collectionName,phoneName,millisSinceGpsEpoch,latDeg,lngDeg", 0) == 0)
    found += " (a GSDC ground-truth table: `pdnav gnss` takes it with --truth-csv)";
  else if (!first.empty() && first.find_first_not_of("0123456789.,-+eE \t\r") == std::string::npos &&
           std::count(first.begin(), first.end(), ',') == 6)
    found += " (numbers without a header, 7 columns: an Oxford step-counter CSV? `pdnav steps --format oxford` reads it)";
  return Format::kAuto;
}

std::string read_head(const std::string& path, std::size_t n) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw IoError(path, 0, std::string("cannot open: ") + std::strerror(errno));
  std::string s(n, '\0');
  f.read(s.data(), static_cast<std::streamsize>(n));
  s.resize(static_cast<std::size_t>(f.gcount()));
  return s;
}

bool is_ole2(const std::string& head) { return head.size() >= 4 && std::memcmp(head.data(), "\xD0\xCF\x11\xE0", 4) == 0; }

[[noreturn]] void not_recognised(const std::string& path, const std::string& found) {
  throw IoError(path, 0, std::string("not a recording pdnav reads: ") + kExpected + "; found " + found);
}

/// A stream that yields `head` (already read from `rest`) and then the rest of `rest`. A pipe
/// (or any file that is not a regular one) can be read once only, so format detection must
/// hand the bytes it looked at to the reader instead of opening the path again.
class PrefixedBuf : public std::streambuf {
 public:
  PrefixedBuf(std::string head, std::unique_ptr<std::istream> rest) : head_(std::move(head)), rest_(std::move(rest)) {
    setg(head_.data(), head_.data(), head_.data() + head_.size());
  }

 protected:
  int_type underflow() override {
    if (gptr() < egptr()) return traits_type::to_int_type(*gptr());
    rest_->read(buf_.data(), static_cast<std::streamsize>(buf_.size()));
    const std::streamsize n = rest_->gcount();
    if (n <= 0) return traits_type::eof();
    setg(buf_.data(), buf_.data(), buf_.data() + n);
    return traits_type::to_int_type(*gptr());
  }

 private:
  std::string head_;
  std::unique_ptr<std::istream> rest_;
  std::array<char, 1 << 16> buf_{};
};

class PrefixedStream : public std::istream {
 public:
  PrefixedStream(std::string head, std::unique_ptr<std::istream> rest)
      : std::istream(nullptr), buf_(std::move(head), std::move(rest)) {
    rdbuf(&buf_);
  }

 private:
  PrefixedBuf buf_;
};

/// A recording that is not a regular file (a named pipe, a device): opened and read once.
std::unique_ptr<SampleSource> open_stream_once(const std::string& path, Format fmt, SourceOptions opt) {
  auto f = std::make_unique<std::ifstream>(path, std::ios::binary);
  if (!*f) throw IoError(path, 0, std::string("cannot open: ") + std::strerror(errno));
  std::string head(std::size_t{1} << 16, '\0');
  f->read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(f->gcount()));
  if (head.empty()) throw IoError(path, 0, "empty input (0 bytes)");
  const std::string name = std::filesystem::path(path).filename().string();
  const auto slurp = [&] {
    std::string all = head;
    all.append(std::istreambuf_iterator<char>(*f), std::istreambuf_iterator<char>());
    return all;
  };
  if (detail::looks_like_zip(head)) return open_memory_source({{name + ".zip", slurp()}}, path, fmt, opt);
  if (detail::looks_like_sensorlogger_json(head)) return open_memory_source({{name + ".json", slurp()}}, path, fmt, opt);
  if (fmt == Format::kAuto) {
    std::string found;
    fmt = sniff_text(head, found);
    if (fmt == Format::kAuto) not_recognised(path, found);
  }
  switch (fmt) {
    case Format::kSession:
    case Format::kGnssLogger:
      return in_time_order(std::make_unique<LogSource>(LogReader(std::make_unique<PrefixedStream>(std::move(head), std::move(f)), path, opt.log),
                                                         fmt, opt.require_samples));
    case Format::kGetSensorData:
      return in_time_order(detail::open_getsensordata(std::make_unique<PrefixedStream>(std::move(head), std::move(f)), path, 0, opt));
    case Format::kSensorLogger:
    case Format::kPhyphox:
      return open_memory_source({{name, slurp()}}, path, fmt, opt);
    case Format::kAuto:
      break;
  }
  not_recognised(path, "nothing");
}

std::unique_ptr<SampleSource> open_container(std::unique_ptr<detail::Container> c, Format fmt, SourceOptions opt) {
  std::string found;
  const Format sniffed = detail::sniff_container(*c, found);
  if (fmt == Format::kAuto) fmt = sniffed;
  if (fmt == Format::kAuto) not_recognised(c->name(), found);
  if (fmt == Format::kSensorLogger) return detail::open_sensorlogger(std::move(c), opt);
  if (fmt == Format::kPhyphox) return detail::open_phyphox(std::move(c), opt);
  throw IoError(c->name(), 0, std::string("a folder or zip cannot be read as ") + std::string(format_name(fmt)) +
                                  " (that format is one text file)");
}

}  // namespace

std::string_view format_name(Format f) {
  for (const auto& n : kNames)
    if (n.f == f) return n.name;
  return "unknown";
}

Format parse_format(std::string_view name) {
  const std::string l = detail::lower_ascii(name);
  for (const auto& n : kNames)
    if (n.name == l) return n.f;
  std::string all;
  for (const auto& n : kNames) all += (all.empty() ? "" : ", ") + std::string(n.name);
  throw std::invalid_argument("unknown format '" + std::string(name) + "' (one of: " + all + ")");
}

std::vector<std::string> format_names() {
  std::vector<std::string> v;
  for (const auto& n : kNames) v.emplace_back(n.name);
  return v;
}

namespace detail {

Format sniff_container(const Container& c, std::string& found) {
  if (c.entries().empty()) { found = "no files"; return Format::kAuto; }
  for (const Entry& e : c.entries()) {
    const std::string p = lower_ascii(e.path);
    if (p == "xl/workbook.xml" || p.find("/xl/workbook.xml") != std::string::npos)
      throw IoError(c.name(), 0, "an Excel workbook (.xlsx; phyphox's Excel export) is not read: export the "
                                 "experiment as CSV (folder or zip) instead");
  }
  if (c.find_path("meta/time.csv") || c.find_path("meta/device.csv")) return Format::kPhyphox;
  const std::string root = c.root();
  std::string names;
  int listed = 0;
  for (const Entry& e : c.entries()) {
    if (listed < 8) names += (listed++ ? ", " : "") + printable(e.path, 60);
    const std::string b = lower_ascii(e.base);
    if (e.size == 0 || b.size() < 4 || b.substr(b.size() - 4) != ".csv") continue;
    std::unique_ptr<EntryStream> s;
    try {
      s = c.open(e);
    } catch (const IoError&) {
      continue;
    }
    std::string line;
    std::getline(s->stream(), line, '\n');
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.size() >= 3 && line.substr(0, 3) == "\xEF\xBB\xBF") line.erase(0, 3);
    if (is_sensorlogger_header(line)) return Format::kSensorLogger;
    if (is_phyphox_header(line)) return Format::kPhyphox;
  }
  if (c.entries().size() > 8) names += ", ...";
  found = std::to_string(c.entries().size()) + " file(s) without a Sensor Logger ('time,seconds_elapsed,...') or "
          "phyphox ('\"Time (s)\",...') CSV header: " + names;
  return Format::kAuto;
}

}  // namespace detail

Format detect_format(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const auto st = fs::status(path, ec);
  if (ec || !fs::exists(st)) throw IoError(path, 0, "cannot open: no such file or folder");
  std::string found;
  if (fs::is_directory(st)) {
    const Format f = detail::sniff_container(*detail::open_folder(path), found);
    if (f == Format::kAuto) not_recognised(path, found);
    return f;
  }
  const std::string head = read_head(path, 1u << 16);
  if (head.empty()) throw IoError(path, 0, "empty file (0 bytes)");
  if (detail::looks_like_zip(head)) {
    const Format f = detail::sniff_container(*detail::open_zip_file(path), found);
    if (f == Format::kAuto) not_recognised(path, found);
    return f;
  }
  if (detail::looks_like_sensorlogger_json(head)) return Format::kSensorLogger;
  if (is_ole2(head))
    throw IoError(path, 0, "an Excel 97 workbook (.xls; phyphox's Excel export) is not read: export the experiment "
                           "as CSV (folder or zip) instead");
  const Format f = sniff_text(head, found);
  if (f == Format::kAuto) not_recognised(path, found);
  return f;
}

std::unique_ptr<SampleSource> open_sample_source(const std::string& path, Format fmt, SourceOptions opt) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const auto st = fs::status(path, ec);
  if (ec || !fs::exists(st)) throw IoError(path, 0, "cannot open: no such file or folder");
  if (fs::is_directory(st)) return open_container(detail::open_folder(path), fmt, opt);
  if (!fs::is_regular_file(st)) return open_stream_once(path, fmt, opt);
  const std::string head = read_head(path, 1u << 16);
  if (detail::looks_like_zip(head)) return open_container(detail::open_zip_file(path), fmt, opt);
  if (detail::looks_like_sensorlogger_json(head) && (fmt == Format::kAuto || fmt == Format::kSensorLogger))
    return open_container(detail::open_json_file(path), Format::kSensorLogger, opt);
  if (fmt == Format::kAuto) fmt = detect_format(path);
  switch (fmt) {
    case Format::kSession:
    case Format::kGnssLogger:
      return in_time_order(std::make_unique<LogSource>(LogReader(path, opt.log), fmt, opt.require_samples));
    case Format::kSensorLogger:
    case Format::kPhyphox: {
      // one CSV of a recording: read it as a recording of that one file
      return open_container(detail::open_single_file(path), fmt, opt);
    }
    case Format::kGetSensorData: {
      auto f = std::make_unique<std::ifstream>(path, std::ios::binary);
      if (!*f) throw IoError(path, 0, std::string("cannot open: ") + std::strerror(errno));
      return in_time_order(detail::open_getsensordata(std::move(f), path, fs::file_size(path, ec), opt));
    }
    case Format::kAuto:
      break;
  }
  not_recognised(path, "nothing");
}

std::unique_ptr<SampleSource> open_memory_source(std::vector<std::pair<std::string, std::string>> files, std::string name,
                                                 Format fmt, SourceOptions opt) {
  if (files.size() == 1 && files[0].first.size() >= 4 &&
      detail::lower_ascii(files[0].first.substr(files[0].first.size() - 4)) == ".zip")
    return open_container(detail::open_zip_bytes(std::move(files[0].second), files[0].first), fmt, opt);
  if (files.size() == 1 && files[0].first.size() >= 5 &&
      detail::lower_ascii(files[0].first.substr(files[0].first.size() - 5)) == ".json")
    return open_container(detail::open_json_bytes(std::move(files[0].second), files[0].first), fmt, opt);
  if (fmt == Format::kSession || fmt == Format::kGnssLogger || fmt == Format::kGetSensorData) {
    if (files.size() != 1) throw IoError(name, 0, "a text log is one file");
    auto in = std::make_unique<std::istringstream>(std::move(files[0].second));
    const std::string file = files[0].first;  // messages name the file
    if (fmt == Format::kGetSensorData) return in_time_order(detail::open_getsensordata(std::move(in), file, 0, opt));
    return in_time_order(std::make_unique<LogSource>(LogReader(std::move(in), file, opt.log), fmt, opt.require_samples));
  }
  return open_container(detail::open_memory_files(std::move(files), name), fmt, opt);
}

}  // namespace pdnav::io
