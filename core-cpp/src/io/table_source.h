// Building blocks of the readers of multi-file recordings (Sensor Logger, phyphox): one CSV
// table per sensor file, read row by row with its header mapped by name, and a k-way merge
// of the per-file streams into one time-ordered SampleSource (one row buffered per file).
#pragma once
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <queue>
#include <string>
#include <string_view>
#include <vector>

#include "io/container.h"
#include "io/line_source.h"
#include "pdnav/io/sample_source.h"

namespace pdnav::io::detail {

/// Why a row is skipped; thrown by row converters. `malformed` rows stop a strict read.
struct RowSkip {
  std::string category;  // the ReadStats::skipped_by_reason key
  std::string detail;
  bool malformed = true;
};

/// Splits one line at `sep`, removing double quotes around fields ("" inside quotes is a quote).
void split_fields(std::string_view line, char sep, std::vector<std::string>& out);

/// One CSV table (a sensor file): header row, then data rows.
class TableFile {
 public:
  /// sep = 0: detected from the header (',' ';' or tab, outside quotes).
  TableFile(const Container& c, const Entry& e, char sep = ',');
  const std::vector<std::string>& header() const { return header_; }
  /// Column of a header name (case-insensitive, trimmed); -1 when absent.
  int column(std::string_view name) const;
  /// Next non-empty data row; false at the end of the file. A torn last line or an
  /// over-long line throws RowSkip (the row is counted as skipped, reading goes on).
  bool next_row();
  std::size_t n_fields() const { return fields_.size(); }
  std::string_view field(int col) const;
  std::int64_t line_no() const { return line_no_; }
  std::int64_t lines() const { return line_no_; }
  const std::string& where() const { return where_; }
  const std::string& base() const { return base_; }
  char sep() const { return sep_; }
  /// Container-level problem (corrupt zip entry, read error), checked at the end.
  std::string error() const;
  std::uint64_t consumed() const { return stream_->consumed(); }
  bool empty_file() const { return header_.empty(); }

 private:
  std::unique_ptr<EntryStream> stream_;
  LineSource src_;
  std::string where_, base_;
  char sep_;
  std::int64_t line_no_ = 0;
  std::vector<std::string> header_;
  std::vector<std::string> fields_;
};

/// Converts the current row of a table into a sample: true = produced, false = row carries
/// nothing (not counted). Throws RowSkip for a bad row.
using RowFn = std::function<bool(const TableFile&, Sample&)>;

/// The k-way merge: per file, the next converted sample; the earliest goes out (ties by the
/// order files were added, so the stream is deterministic).
class MergedSource : public SampleSource {
 public:
  MergedSource(std::string name, Format fmt, SourceOptions opt, std::uint64_t total_bytes);
  void add(std::unique_ptr<TableFile> f, RowFn fn);
  /// Samples emitted before every other (Meta rows); their t_ns is set to the first time.
  void add_prefix(Sample s) { prefix_.push_back(std::move(s)); }
  std::map<std::string, std::string>& info() { return info_; }
  ReadStats& mutable_stats() { return stats_; }
  /// Appended to the "no samples" error (e.g. "pass the recording's folder or zip").
  void set_hint(std::string h) { hint_ = std::move(h); }

  bool next(Sample& out) override;
  const ReadStats& stats() const override;
  double progress() const override;
  const std::string& name() const override { return name_; }
  const std::map<std::string, std::string>& header_info() const override { return info_; }
  Format format() const override { return format_; }

 private:
  struct Cursor {
    std::unique_ptr<TableFile> file;
    RowFn fn;
    Sample head;
    TimeNs last_t = 0;
    bool any = false;
    bool done = false;
  };
  bool advance(Cursor& c);
  void skip(const TableFile& f, const RowSkip& s);
  void start();
  void finish_empty();  // the "no samples" error when nothing was read (once)

  std::string name_;
  Format format_;
  SourceOptions opt_;
  std::uint64_t total_bytes_;
  std::vector<Cursor> cursors_;
  std::vector<Sample> prefix_;
  std::size_t prefix_next_ = 0;
  bool started_ = false, finished_ = false;
  using Key = std::pair<TimeNs, std::size_t>;
  std::priority_queue<Key, std::vector<Key>, std::greater<Key>> heap_;
  std::map<std::string, std::string> info_;
  mutable ReadStats stats_;
  std::map<std::string, std::int64_t> by_type_;
  std::string hint_;
};

}  // namespace pdnav::io::detail
