// The one reader of the session log format (docs/log-format.md), a superset of Google's
// GnssLogger v3. Streams line by line (constant memory), maps columns by the header names
// of each line type, counts and reports every skipped line with file:line and reason.
#pragma once
#include <cstdint>
#include <istream>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "pdnav/geo/samples.h"

namespace pdnav::io {

/// An input error that names where it happened. what() is "file:line: reason".
class IoError : public std::runtime_error {
 public:
  IoError(std::string file, std::int64_t line, std::string reason);
  const std::string& file() const { return file_; }
  std::int64_t line() const { return line_; }
  const std::string& reason() const { return reason_; }

 private:
  std::string file_;
  std::int64_t line_;
  std::string reason_;
};

/// One skipped or suspicious line.
struct LogIssue {
  std::string file;
  std::int64_t line = 0;
  std::string reason;
  std::string to_string() const;  // "file:line: reason"
};

struct ReadStats {
  std::int64_t lines = 0;            // physical lines read
  std::int64_t samples = 0;          // samples returned
  std::map<std::string, std::int64_t> samples_by_type;  // "Accel" -> n
  std::map<std::string, std::int64_t> skipped_by_reason; // "unknown line type 'Foo'" -> n
  std::vector<LogIssue> issues;      // the first max_reported_issues skipped lines
  /// Files (or columns) of a multi-file recording that carry nothing the core uses, with why
  /// ("Gravity.csv" -> "gravity alone; TotalAcceleration is read"). Not skipped lines.
  std::map<std::string, std::string> not_used;
  /// Motion-sensor samples a log written in arrival order held after later ones of another
  /// sensor, released in time order (open_sample_source), and the widest lateness seen, s.
  std::int64_t reordered = 0;
  double reorder_window_s = 0.0;
  std::int64_t skipped_total() const;
};

struct LogReaderOptions {
  bool strict = false;                 // throw IoError on the first malformed line
  std::size_t max_reported_issues = 100;
  /// Lines whose time goes backwards relative to the previous line of the same type are
  /// skipped and counted (equal times are kept).
  bool drop_backwards_time = true;
};

class LogReader {
 public:
  /// Opens a file; throws IoError(path, 0, reason) when it cannot be read.
  explicit LogReader(const std::string& path, LogReaderOptions opt = {});
  /// Reads from a stream; `name` is used in messages.
  LogReader(std::unique_ptr<std::istream> in, std::string name, LogReaderOptions opt = {});
  ~LogReader();
  LogReader(LogReader&&) noexcept;
  LogReader& operator=(LogReader&&) noexcept;

  /// Next sample in file order; false at end of input. Malformed lines are skipped
  /// (counted in stats()) unless options.strict.
  bool next(Sample& out);

  const ReadStats& stats() const;
  /// "key: value" pairs from the header comment (e.g. Version, Platform, Manufacturer, Model).
  const std::map<std::string, std::string>& header_info() const;
  /// Fraction of the input consumed, 0..1 (files only; streams report 0).
  double progress() const;
  const std::string& name() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pdnav::io
