#include "io/table_source.h"

#include <algorithm>
#include <limits>

#include "io/skip_reasons.h"
#include "io/text.h"
#include "pdnav/io/log_format.h"

namespace pdnav::io::detail {

void split_fields(std::string_view line, char sep, std::vector<std::string>& out) {
  out.clear();
  std::string cur;
  bool quoted = false, was_quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"') {
        if (i + 1 < line.size() && line[i + 1] == '"') { cur.push_back('"'); ++i; }
        else quoted = false;
      } else {
        cur.push_back(c);
      }
    } else if (c == '"' && std::string(trim(cur)).empty()) {
      quoted = true;
      was_quoted = true;
      cur.clear();
    } else if (c == sep) {
      out.emplace_back(was_quoted ? cur : std::string(trim(cur)));
      cur.clear();
      was_quoted = false;
    } else {
      cur.push_back(c);
    }
  }
  out.emplace_back(was_quoted ? cur : std::string(trim(cur)));
}

namespace {
char detect_sep(std::string_view header) {
  int comma = 0, semi = 0, tab = 0;
  bool quoted = false;
  for (char c : header) {
    if (c == '"') quoted = !quoted;
    else if (!quoted && c == ',') ++comma;
    else if (!quoted && c == ';') ++semi;
    else if (!quoted && c == '\t') ++tab;
  }
  if (tab > 0 && tab >= comma && tab >= semi) return '\t';
  if (semi > comma) return ';';
  return ',';
}
}  // namespace

TableFile::TableFile(const Container& c, const Entry& e, char sep)
    : stream_(c.open(e)), src_(stream_->stream()), where_(c.where(e)), base_(e.base), sep_(sep) {
  Line line;
  while (src_.next(line)) {
    ++line_no_;
    std::string_view text = line.text;
    if (line_no_ == 1 && text.size() >= 3 && text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // UTF-8 BOM
    if (trim(text).empty()) continue;
    if (line.too_long) throw IoError(where_, line_no_, "header line longer than " + std::to_string(LineSource::kMaxLineBytes) + " bytes");
    if (sep_ == 0) sep_ = detect_sep(text);
    split_fields(text, sep_, header_);
    break;
  }
}

int TableFile::column(std::string_view name) const {
  const std::string want = lower_ascii(trim(name));
  for (std::size_t i = 0; i < header_.size(); ++i)
    if (lower_ascii(trim(header_[i])) == want) return static_cast<int>(i);
  return -1;
}

bool TableFile::next_row() {
  Line line;
  while (src_.next(line)) {
    ++line_no_;
    if (trim(line.text).empty()) continue;
    if (line.too_long) throw RowSkip{kTooLong, "longer than " + std::to_string(LineSource::kMaxLineBytes) + " bytes"};
    split_fields(line.text, sep_, fields_);
    if (!line.terminated && fields_.size() != header_.size())
      throw RowSkip{kTorn, "no newline at end of file and " + std::to_string(fields_.size()) + " of " +
                               std::to_string(header_.size()) + " fields"};
    return true;
  }
  return false;
}

std::string_view TableFile::field(int col) const {
  if (col < 0 || static_cast<std::size_t>(col) >= fields_.size()) return {};
  return fields_[static_cast<std::size_t>(col)];
}

std::string TableFile::error() const {
  std::string e = stream_->error();
  if (e.empty() && src_.read_error()) e = "read error";
  return e;
}

MergedSource::MergedSource(std::string name, Format fmt, SourceOptions opt, std::uint64_t total_bytes)
    : name_(std::move(name)), format_(fmt), opt_(opt), total_bytes_(total_bytes) {}

void MergedSource::add(std::unique_ptr<TableFile> f, RowFn fn) {
  stats_.lines += f->lines();
  Cursor c;
  c.file = std::move(f);
  c.fn = std::move(fn);
  cursors_.push_back(std::move(c));
}

void MergedSource::skip(const TableFile& f, const RowSkip& s) {
  if (s.malformed && opt_.log.strict) throw IoError(f.where(), f.line_no(), s.category + (s.detail.empty() ? "" : ": " + s.detail));
  ++stats_.skipped_by_reason[s.category];
  if (stats_.issues.size() < opt_.log.max_reported_issues)
    stats_.issues.push_back(LogIssue{f.where(), f.line_no(), s.category + (s.detail.empty() ? "" : ": " + s.detail)});
}

bool MergedSource::advance(Cursor& c) {
  if (c.done) return false;
  TableFile& f = *c.file;
  for (;;) {
    const std::int64_t before = f.line_no();
    bool have = false;
    try {
      have = f.next_row();
    } catch (const RowSkip& s) {
      stats_.lines += f.line_no() - before;
      skip(f, s);
      continue;
    }
    stats_.lines += f.line_no() - before;
    if (!have) break;
    try {
      if (!c.fn(f, c.head)) continue;
      const TimeNs t = sample_time_ns(c.head);
      if (c.any && t < c.last_t && opt_.log.drop_backwards_time)
        throw RowSkip{kBackwards, "t=" + std::to_string(t) + " ns < previous t=" + std::to_string(c.last_t) + " ns in this file"};
      c.last_t = t;
      c.any = true;
      return true;
    } catch (const RowSkip& s) {
      skip(f, s);
    }
  }
  c.done = true;
  const std::string err = f.error();
  if (!err.empty()) throw IoError(f.where(), f.line_no(), err);
  return false;
}

void MergedSource::start() {
  started_ = true;
  for (std::size_t i = 0; i < cursors_.size(); ++i)
    if (advance(cursors_[i])) heap_.emplace(sample_time_ns(cursors_[i].head), i);
  if (heap_.empty() && opt_.require_samples) finish_empty();  // metadata alone is no recording
  const TimeNs t0 = heap_.empty() ? 0 : heap_.top().first;
  for (Sample& s : prefix_) std::visit([t0](auto& x) { x.t_ns = t0; }, s);
}

bool MergedSource::next(Sample& out) {
  if (!started_) start();
  if (prefix_next_ < prefix_.size()) {
    out = prefix_[prefix_next_++];
  } else if (!heap_.empty()) {
    const std::size_t i = heap_.top().second;
    heap_.pop();
    Cursor& c = cursors_[i];
    out = std::move(c.head);
    if (advance(c)) heap_.emplace(sample_time_ns(c.head), i);
  } else {
    finish_empty();
    return false;
  }
  ++stats_.samples;
  ++by_type_[std::string(line_type_name(out))];
  return true;
}

void MergedSource::finish_empty() {
  {
    if (!finished_) {  // once
      finished_ = true;
      if (opt_.require_samples && stats_.samples == 0) {
        std::string why = "no samples: " + std::to_string(stats_.lines) + " lines read, " +
                          std::to_string(stats_.skipped_total()) + " rows skipped";
        if (!stats_.issues.empty()) why += " (first: " + stats_.issues.front().to_string() + ")";
        int n = 0;
        for (const auto& [what, reason] : stats_.not_used)
          if (n++ < 3) why += "; not used: " + what + ": " + reason;
        if (!hint_.empty()) why += "; " + hint_;
        throw IoError(name_, 0, why);
      }
    }
  }
}

const ReadStats& MergedSource::stats() const {
  stats_.samples_by_type = by_type_;
  return stats_;
}

double MergedSource::progress() const {
  if (total_bytes_ == 0) return 0.0;
  std::uint64_t n = 0;
  for (const Cursor& c : cursors_) n += c.file->consumed();
  return std::min(1.0, static_cast<double>(n) / static_cast<double>(total_bytes_));
}

}  // namespace pdnav::io::detail
