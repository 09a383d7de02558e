// Line-by-line reading of the text products (RINEX clock, SP3) with the line number for
// "name:line: reason" errors. Private to the gnss module.
#pragma once
#include <istream>
#include <stdexcept>
#include <string>
#include <utility>

namespace pdnav::gnss::detail {

class LineReader {
 public:
  /// How an empty line is handed out: as it is, or as one blank (SP3: a parser that looks at
  /// the first column of every line then needs no empty-line check).
  enum class EmptyLine { kKeep, kAsBlank };

  LineReader(std::istream& in, std::string name, EmptyLine empty = EmptyLine::kKeep)
      : in_(in), name_(std::move(name)), empty_(empty) {}

  /// The next line without its CR (CRLF files); false at the end of the stream.
  bool next(std::string& l) {
    if (!std::getline(in_, l)) return false;
    if (!l.empty() && l.back() == '\r') l.pop_back();
    ++line_no_;
    if (empty_ == EmptyLine::kAsBlank && l.empty()) l = " ";
    return true;
  }

  /// Throws std::runtime_error("name:line: reason") for the line last read.
  [[noreturn]] void fail(const std::string& reason) const {
    throw std::runtime_error(name_ + ":" + std::to_string(line_no_) + ": " + reason);
  }

 private:
  std::istream& in_;
  std::string name_;
  EmptyLine empty_;
  int line_no_ = 0;
};

}  // namespace pdnav::gnss::detail
