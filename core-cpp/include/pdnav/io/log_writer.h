// The one writer of the session log format. Used by the app (through JNI), the simulator and
// the CLI. Crash-safe: lines are buffered and handed to the OS whole, at least every
// flush_interval of sample time and on close; a killed process loses at most that interval
// and never leaves a torn line (a torn last line from a power cut is skipped by the reader).
#pragma once
#include <cstdint>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "pdnav/geo/samples.h"

namespace pdnav::io {

struct LogWriterOptions {
  TimeNs flush_interval_ns = kNsPerS;  // hand buffered lines to the OS at least this often
  bool fsync_on_flush = false;         // also fsync (power-cut safety; costs battery)
  std::string device = "";             // written as a header comment
};

class LogWriter {
 public:
  /// Creates (truncates) a file and writes the header (format version + column names of
  /// every line type). Throws IoError when the file cannot be created.
  explicit LogWriter(const std::string& path, LogWriterOptions opt = {});
  /// Writes to a stream (tests); flushing goes to the stream.
  LogWriter(std::unique_ptr<std::ostream> out, std::string name, LogWriterOptions opt = {});
  ~LogWriter();  // flushes and closes; never throws
  LogWriter(LogWriter&&) noexcept;
  LogWriter& operator=(LogWriter&&) noexcept;

  void write(const Sample& s);
  void flush();
  void close();
  std::int64_t lines_written() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The header comment block the writer emits (also documents the format).
std::string log_header(const std::string& device = "");
/// One sample as one log line (no newline), exactly as LogWriter writes it.
std::string format_line(const Sample& s);

}  // namespace pdnav::io
