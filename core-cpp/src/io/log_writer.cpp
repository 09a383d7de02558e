// LogWriter: the one writer of the session log format (docs/log-format.md).
#include "pdnav/io/log_writer.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <variant>

#include "io/schema.h"
#include "io/text.h"
#include "pdnav/io/log_format.h"
#include "pdnav/io/log_reader.h"

namespace pdnav::io {
namespace {

/// Appends the fields of one sample in the canonical column order.
struct FieldWriter {
  std::string& out;
  void sep() { out.push_back(','); }
  void elapsed(std::string_view, TimeNs& t) { sep(); detail::append_i64(out, t); }
  void i64(std::string_view, std::int64_t& x) {
    sep();
    if (x != kMissingInt) detail::append_i64(out, x);
  }
  void i32(std::string_view, int& x) { sep(); detail::append_i64(out, x); }
  void f64(std::string_view, double& x) { sep(); detail::append_f64(out, x); }
  void hpa(std::string_view, double& pa) { sep(); detail::append_f64_pow10(out, pa, 2); }
  void flag(std::string_view, bool& b) { sep(); out.push_back(b ? '1' : '0'); }
  void text(std::string_view, std::string& s) { sep(); detail::append_escaped(out, s); }
  void bytes(std::string_view, std::vector<std::uint8_t>& d) {
    for (std::uint8_t b : d) {  // signed, as GnssLogger writes Java bytes
      sep();
      detail::append_i64(out, static_cast<std::int8_t>(b));
    }
  }
};

void append_line(std::string& out, const Sample& s) {
  std::visit(
      [&](const auto& x) {
        using S = std::decay_t<decltype(x)>;
        out.append(detail::LineTraits<S>::name);
        FieldWriter w{out};
        detail::visit_fields(const_cast<S&>(x), w);  // FieldWriter only reads
      },
      s);
}

std::string one_line(std::string_view s) {
  std::string out(s);
  for (char& c : out)
    if (c == '\n' || c == '\r') c = ' ';
  return out;
}

constexpr std::size_t kMaxBufferBytes = 1u << 20;  // hand over early when this much is pending

}  // namespace

std::string log_header(const std::string& device) {
  std::string h = "# Header Description:\n#\n# Version: pdnav-log " + std::to_string(kLogFormatVersion) +
                  " Format: GnssLogger-v3-superset\n";
  if (!device.empty()) h += "# Device: " + one_line(device) + "\n";
  h += "#\n";
  for (std::string_view type : line_type_names()) {
    h += "# ";
    bool first = true;
    for (const std::string& c : default_columns(type)) {
      if (!first) h += ',';
      h += c;
      first = false;
    }
    h += "\n#\n";
  }
  return h;
}

std::string format_line(const Sample& s) {
  std::string out;
  append_line(out, s);
  return out;
}

struct LogWriter::Impl {
  std::string name;
  LogWriterOptions opt;
  int fd = -1;
  std::unique_ptr<std::ostream> out;
  std::string buf;
  std::int64_t lines = 0;        // sample lines
  std::int64_t file_lines = 0;   // all lines, for error positions
  bool have_flush_t = false;
  TimeNs last_flush_t = 0;
  bool closed = false;

  [[noreturn]] void fail(const std::string& what) const { throw IoError(name, file_lines, what); }

  void write_fd(const char* p, std::size_t n) {
    while (n > 0) {
      const ssize_t w = ::write(fd, p, n);
      if (w < 0) {
        if (errno == EINTR) continue;
        fail(std::string("write failed: ") + std::strerror(errno));
      }
      p += w;
      n -= static_cast<std::size_t>(w);
    }
    if (opt.fsync_on_flush && ::fsync(fd) != 0) fail(std::string("fsync failed: ") + std::strerror(errno));
  }

  /// Hands every buffered (whole) line to the OS or the stream.
  void hand_over() {
    if (buf.empty()) return;
    std::string pending;
    pending.swap(buf);  // on failure the lines are dropped, not retried forever
    if (fd >= 0) {
      write_fd(pending.data(), pending.size());
    } else if (out) {
      out->write(pending.data(), static_cast<std::streamsize>(pending.size()));
      out->flush();
      if (!*out) fail("write failed (stream error)");
    }
    pending.clear();
    if (buf.capacity() < pending.capacity()) buf.swap(pending);  // keep the allocation
  }

  void begin(const std::string& device) {
    buf = log_header(device);
    for (char c : buf) file_lines += c == '\n';
    hand_over();
  }
};

LogWriter::LogWriter(const std::string& path, LogWriterOptions opt) : impl_(std::make_unique<Impl>()) {
  impl_->name = path;
  impl_->opt = opt;
  impl_->fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (impl_->fd < 0) throw IoError(path, 0, std::string("cannot create: ") + std::strerror(errno));
  try {
    impl_->begin(opt.device);
  } catch (...) {
    ::close(impl_->fd);
    impl_->fd = -1;
    impl_->closed = true;
    throw;
  }
}

LogWriter::LogWriter(std::unique_ptr<std::ostream> out, std::string name, LogWriterOptions opt)
    : impl_(std::make_unique<Impl>()) {
  impl_->name = std::move(name);
  impl_->opt = opt;
  if (!out) throw IoError(impl_->name, 0, "null stream");
  impl_->out = std::move(out);
  impl_->begin(opt.device);
}

LogWriter::~LogWriter() {
  try {
    if (impl_) close();
  } catch (...) {
    // never throws; a caller who cares calls close() and sees the IoError
  }
}

LogWriter::LogWriter(LogWriter&&) noexcept = default;
LogWriter& LogWriter::operator=(LogWriter&& other) noexcept {
  if (this != &other) {
    try {
      if (impl_) close();
    } catch (...) {
    }
    impl_ = std::move(other.impl_);
  }
  return *this;
}

void LogWriter::write(const Sample& s) {
  Impl& m = *impl_;
  if (m.closed) m.fail("write after close");
  append_line(m.buf, s);
  m.buf.push_back('\n');
  ++m.lines;
  ++m.file_lines;
  const TimeNs t = sample_time_ns(s);
  if (!m.have_flush_t) {
    m.have_flush_t = true;
    m.last_flush_t = t;
  }
  TimeNs since = 0;
  const bool overflow = __builtin_sub_overflow(t, m.last_flush_t, &since);
  if ((!overflow && since >= m.opt.flush_interval_ns) || (overflow && t > m.last_flush_t) ||
      m.buf.size() >= kMaxBufferBytes) {
    m.hand_over();
    m.last_flush_t = t;
  }
}

void LogWriter::flush() {
  if (impl_->closed) return;
  impl_->hand_over();
}

void LogWriter::close() {
  Impl& m = *impl_;
  if (m.closed) return;
  m.closed = true;
  try {
    m.hand_over();
  } catch (...) {
    if (m.fd >= 0) ::close(m.fd);
    m.fd = -1;
    throw;
  }
  if (m.fd >= 0) {
    const int fd = m.fd;
    m.fd = -1;
    if (::close(fd) != 0) m.fail(std::string("close failed: ") + std::strerror(errno));
  } else if (m.out) {
    m.out->flush();
  }
}

std::int64_t LogWriter::lines_written() const { return impl_->lines; }

}  // namespace pdnav::io
