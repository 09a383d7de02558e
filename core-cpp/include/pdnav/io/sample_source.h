// The one face every log consumer reads through (replay, inspect, eval-*, gnss, rinex, the
// JNI reader): a time-ordered stream of pdnav::Sample from any recording format pdnav knows.
// The format is detected from the content (docs/log-format.md, "Other loggers"), or forced.
// Implementations: the session/GnssLogger LogReader, Sensor Logger (folder or zip), phyphox
// (CSV export folder or zip), GetSensorData (IPIN logger text file).
#pragma once
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "pdnav/geo/samples.h"
#include "pdnav/io/log_reader.h"

namespace pdnav::io {

enum class Format {
  kAuto,           // detect from content
  kSession,        // pdnav session log (GnssLogger superset)
  kGnssLogger,     // Google GnssLogger .txt (the same reader as kSession)
  kSensorLogger,   // Sensor Logger (Kelvin Choi), folder or zip of one CSV per sensor
  kPhyphox,        // phyphox CSV export, folder or zip
  kGetSensorData,  // GetSensorData (IPIN competition logger), one text file
};

/// "auto", "session", "gnsslogger", "sensorlogger", "phyphox", "getsensordata".
std::string_view format_name(Format f);
/// Inverse of format_name; throws std::invalid_argument naming the accepted names.
Format parse_format(std::string_view name);
/// Every name parse_format accepts (for --help and error messages).
std::vector<std::string> format_names();

struct SourceOptions {
  LogReaderOptions log;  // strict, issue cap, backwards-time policy (all readers honour them)
  /// A recording that yields no sample at all is an error (IoError at the end of input),
  /// never an empty success.
  bool require_samples = true;
};

/// A time-ordered stream of samples from one recording.
class SampleSource {
 public:
  virtual ~SampleSource() = default;
  /// Next sample; false at the end of input. Skipped lines are counted in stats().
  virtual bool next(Sample& out) = 0;
  /// Samples by type, skipped lines by reason (file:line for the first ones), files not used.
  virtual const ReadStats& stats() const = 0;
  /// Fraction of the input consumed, 0..1.
  virtual double progress() const = 0;
  virtual const std::string& name() const = 0;
  /// Header / metadata "key: value" pairs (session header; Sensor Logger Metadata.csv, ...).
  virtual const std::map<std::string, std::string>& header_info() const = 0;
  /// The format actually read (never kAuto).
  virtual Format format() const = 0;
};

/// What `path` holds, from its content (a folder's file names and headers, a zip's entry
/// names, a file's first lines). Throws IoError naming what was expected and what was found
/// when no reader recognises it.
Format detect_format(const std::string& path);

/// Opens `path` (file, folder or zip) as a sample source; `fmt` forces the reader.
/// Throws IoError when it cannot be read or is not of the format asked for.
std::unique_ptr<SampleSource> open_sample_source(const std::string& path, Format fmt = Format::kAuto,
                                                 SourceOptions opt = {});

/// A Sensor Logger / phyphox / GetSensorData recording held in memory (tests, fuzzers):
/// `files` maps a file name inside the recording ("Gyroscope.csv", "meta/time.csv") to its
/// bytes; a single entry named "*.zip" is read as a zip archive.
std::unique_ptr<SampleSource> open_memory_source(std::vector<std::pair<std::string, std::string>> files,
                                                 std::string name, Format fmt, SourceOptions opt = {});

}  // namespace pdnav::io
