#include "io/line_source.h"

#include <cstring>

namespace pdnav::io::detail {

LineSource::LineSource(std::istream& in, std::size_t buffer_bytes)
    : in_(in), buf_(new char[buffer_bytes]), size_(buffer_bytes) {}

bool LineSource::refill() {
  if (eof_) return false;
  pos_ = 0;
  end_ = 0;
  in_.read(buf_.get(), static_cast<std::streamsize>(size_));
  const std::streamsize got = in_.gcount();
  end_ = got > 0 ? static_cast<std::size_t>(got) : 0;
  if (!in_) {
    if (in_.bad()) read_error_ = true;
    eof_ = true;
  }
  return end_ > 0;
}

void LineSource::append_long(const char* p, std::size_t n) {
  const std::size_t room = kMaxLineBytes - std::min(kMaxLineBytes, long_.size());
  if (n > room) long_too_long_ = true;
  long_.append(p, std::min(n, room));
}

bool LineSource::next(Line& line) {
  long_.clear();
  long_too_long_ = false;
  bool have_partial = false;
  for (;;) {
    if (pos_ >= end_ && !refill()) break;
    const char* start = buf_.get() + pos_;
    const std::size_t avail = end_ - pos_;
    const void* nl = std::memchr(start, '\n', avail);
    if (nl == nullptr) {
      append_long(start, avail);
      consumed_ += avail;
      pos_ = end_;
      have_partial = true;
      continue;
    }
    const auto n = static_cast<std::size_t>(static_cast<const char*>(nl) - start);
    consumed_ += n + 1;
    pos_ += n + 1;
    std::string_view text;
    if (!have_partial && n <= kMaxLineBytes) {
      text = std::string_view(start, n);
    } else {
      append_long(start, n);
      text = long_;
    }
    if (!text.empty() && text.back() == '\r') text.remove_suffix(1);
    line = Line{text, true, long_too_long_ || n > kMaxLineBytes};
    if (line.too_long && line.text.size() > kMaxLineBytes) line.text = line.text.substr(0, kMaxLineBytes);
    return true;
  }
  if (!have_partial) return false;
  std::string_view text = long_;
  if (!text.empty() && text.back() == '\r') text.remove_suffix(1);
  line = Line{text, false, long_too_long_};
  return true;
}

}  // namespace pdnav::io::detail
