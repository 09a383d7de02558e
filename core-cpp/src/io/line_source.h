// Buffered line splitter over a std::istream with a cap on the line length, so memory stays
// constant whatever the input (a 1 GB log, or a 1 GB line without a newline).
#pragma once
#include <cstdint>
#include <istream>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace pdnav::io::detail {

struct Line {
  std::string_view text;    // without the '\n' and a trailing '\r'; valid until the next call
  bool terminated = true;   // false: the input ended without a newline after this line
  bool too_long = false;    // longer than the cap; text holds only the first cap bytes
};

class LineSource {
 public:
  static constexpr std::size_t kMaxLineBytes = 1u << 20;

  explicit LineSource(std::istream& in, std::size_t buffer_bytes = 1u << 16);
  /// Next line; false at the end of the input. Throws std::ios_base::failure-free:
  /// a stream error sets read_error() and ends the input.
  bool next(Line& line);
  std::uint64_t bytes_consumed() const { return consumed_; }
  bool read_error() const { return read_error_; }

 private:
  bool refill();
  void append_long(const char* p, std::size_t n);

  std::istream& in_;
  std::unique_ptr<char[]> buf_;  // not zero-filled
  std::size_t size_;
  std::size_t pos_ = 0, end_ = 0;
  bool eof_ = false;
  bool read_error_ = false;
  std::uint64_t consumed_ = 0;
  std::string long_;        // a line that spans buffer refills
  bool long_too_long_ = false;
};

}  // namespace pdnav::io::detail
