// Folders, zip archives and in-memory file sets as recordings of several files.
// Zip: the central directory is read once (zip64 sizes and offsets understood); each entry is
// inflated on demand through zlib's raw deflate (windowBits -15) with a 64 KiB input buffer,
// its CRC-32 and size checked at its end. Stored (method 0) and deflate (8) entries; anything
// else (encrypted, bzip2, ...) is refused with the entry's name.
#include "io/container.h"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <streambuf>
#include <system_error>

#include "pdnav/io/log_reader.h"

namespace pdnav::io::detail {

namespace {

std::string lower(std::string s) {
  for (char& c : s)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return s;
}

std::string base_of(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

std::string dir_of(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string() : path.substr(0, slash);
}

/// A plain stream over a file or a string, counting consumed bytes through tellg.
class PlainEntryStream : public EntryStream {
 public:
  explicit PlainEntryStream(std::unique_ptr<std::istream> in) : in_(std::move(in)) {}
  std::istream& stream() override { return *in_; }
  std::uint64_t consumed() const override {
    const auto pos = in_->rdbuf()->pubseekoff(0, std::ios::cur, std::ios::in);
    return pos < 0 ? 0 : static_cast<std::uint64_t>(pos);
  }

 private:
  std::unique_ptr<std::istream> in_;
};

// ---- zip ------------------------------------------------------------------------------

constexpr int kEncrypted = 1 << 20;  // Entry::method of an encrypted entry

std::uint16_t u16(const unsigned char* p) { return static_cast<std::uint16_t>(p[0] | (p[1] << 8)); }
std::uint32_t u32(const unsigned char* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}
std::uint64_t u64(const unsigned char* p) {
  return static_cast<std::uint64_t>(u32(p)) | (static_cast<std::uint64_t>(u32(p + 4)) << 32);
}

/// Random access to the archive bytes (a file or a shared string).
class Bytes {
 public:
  virtual ~Bytes() = default;
  virtual std::uint64_t size() const = 0;
  /// Reads exactly n bytes at off; false when beyond the end or on a read error.
  virtual bool read(std::uint64_t off, void* dst, std::size_t n) const = 0;
  /// A fresh stream positioned at off (one per open entry).
  virtual std::unique_ptr<std::istream> stream_at(std::uint64_t off) const = 0;
};

class FileBytes : public Bytes {
 public:
  FileBytes(std::string path, std::uint64_t size) : path_(std::move(path)), size_(size), in_(path_, std::ios::binary) {
    if (!in_) throw IoError(path_, 0, std::string("cannot open: ") + std::strerror(errno));
  }
  std::uint64_t size() const override { return size_; }
  bool read(std::uint64_t off, void* dst, std::size_t n) const override {
    if (off > size_ || n > size_ - off) return false;
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(off));
    in_.read(static_cast<char*>(dst), static_cast<std::streamsize>(n));
    return static_cast<std::size_t>(in_.gcount()) == n;
  }
  std::unique_ptr<std::istream> stream_at(std::uint64_t off) const override {
    auto f = std::make_unique<std::ifstream>(path_, std::ios::binary);
    if (!*f) throw IoError(path_, 0, std::string("cannot open: ") + std::strerror(errno));
    f->seekg(static_cast<std::streamoff>(off));
    return f;
  }

 private:
  std::string path_;
  std::uint64_t size_;
  mutable std::ifstream in_;
};

/// A read-only streambuf over a shared string (no copy per entry).
class SharedStringBuf : public std::streambuf {
 public:
  SharedStringBuf(std::shared_ptr<const std::string> s, std::uint64_t off) : s_(std::move(s)) {
    char* b = const_cast<char*>(s_->data());
    const std::size_t o = static_cast<std::size_t>(std::min<std::uint64_t>(off, s_->size()));
    setg(b, b + o, b + s_->size());
  }

 private:
  std::shared_ptr<const std::string> s_;
};
class SharedStringStream : public std::istream {
 public:
  SharedStringStream(std::shared_ptr<const std::string> s, std::uint64_t off) : std::istream(nullptr), buf_(std::move(s), off) {
    rdbuf(&buf_);
  }

 private:
  SharedStringBuf buf_;
};

class StringBytes : public Bytes {
 public:
  explicit StringBytes(std::string s) : s_(std::make_shared<const std::string>(std::move(s))) {}
  std::uint64_t size() const override { return s_->size(); }
  bool read(std::uint64_t off, void* dst, std::size_t n) const override {
    if (off > s_->size() || n > s_->size() - off) return false;
    std::memcpy(dst, s_->data() + off, n);
    return true;
  }
  std::unique_ptr<std::istream> stream_at(std::uint64_t off) const override {
    return std::make_unique<SharedStringStream>(s_, off);
  }

 private:
  std::shared_ptr<const std::string> s_;
};

/// Inflates (or copies, method 0) one zip entry from a stream positioned at its data.
class InflateBuf : public std::streambuf {
 public:
  InflateBuf(std::unique_ptr<std::istream> src, const Entry& e) : src_(std::move(src)), e_(e) {
    std::memset(&z_, 0, sizeof z_);
    if (e_.method == 8 && inflateInit2(&z_, -MAX_WBITS) != Z_OK) error_ = "zlib inflateInit2 failed";
    else z_ready_ = e_.method == 8;
  }
  ~InflateBuf() override {
    if (z_ready_) inflateEnd(&z_);
  }
  const std::string& error() const { return error_; }
  std::uint64_t consumed() const { return comp_read_; }

 protected:
  int_type underflow() override {
    if (gptr() < egptr()) return traits_type::to_int_type(*gptr());
    if (done_ || !error_.empty()) return traits_type::eof();
    const std::size_t got = e_.method == 0 ? fill_stored() : fill_deflate();
    if (got > 0) {
      crc_ = crc32(crc_, reinterpret_cast<const Bytef*>(out_.data()), static_cast<uInt>(got));
      out_total_ += got;
      setg(out_.data(), out_.data(), out_.data() + got);
    }
    if (done_) finish();
    if (got == 0) return traits_type::eof();
    return traits_type::to_int_type(*gptr());
  }

 private:
  std::size_t read_src(char* dst, std::size_t want) {
    const std::uint64_t left = e_.comp_size - comp_read_;
    const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(want, left));
    if (n == 0) return 0;
    src_->read(dst, static_cast<std::streamsize>(n));
    const auto got = static_cast<std::size_t>(src_->gcount());
    comp_read_ += got;
    if (got < n) error_ = "archive ends inside the entry (truncated zip?)";
    return got;
  }
  std::size_t fill_stored() {
    const std::size_t got = read_src(out_.data(), out_.size());
    if (comp_read_ >= e_.comp_size) done_ = true;
    return got;
  }
  std::size_t fill_deflate() {
    z_.next_out = reinterpret_cast<Bytef*>(out_.data());
    z_.avail_out = static_cast<uInt>(out_.size());
    while (z_.avail_out == out_.size() && error_.empty() && !done_) {
      if (z_.avail_in == 0) {
        const std::size_t got = read_src(in_.data(), in_.size());
        if (got == 0) {
          if (error_.empty()) error_ = "deflate data ends early (corrupt zip entry)";
          break;
        }
        z_.next_in = reinterpret_cast<Bytef*>(in_.data());
        z_.avail_in = static_cast<uInt>(got);
      }
      const int rc = inflate(&z_, Z_NO_FLUSH);
      if (rc == Z_STREAM_END) done_ = true;
      else if (rc != Z_OK && rc != Z_BUF_ERROR)
        error_ = std::string("corrupt deflate data (zlib: ") + (z_.msg ? z_.msg : "error") + ")";
      else if (rc == Z_BUF_ERROR && z_.avail_in > 0)
        error_ = "corrupt deflate data (zlib: no progress)";
    }
    return out_.size() - z_.avail_out;
  }
  void finish() {
    if (!error_.empty()) return;
    if (out_total_ != e_.size)
      error_ = "entry size " + std::to_string(out_total_) + " bytes, central directory says " + std::to_string(e_.size);
    else if (crc_ != e_.crc32)
      error_ = "CRC-32 mismatch (corrupt zip entry)";
  }

  std::unique_ptr<std::istream> src_;
  Entry e_;
  z_stream z_;
  bool z_ready_ = false;
  bool done_ = false;
  std::string error_;
  std::uint64_t comp_read_ = 0, out_total_ = 0;
  uLong crc_ = crc32(0L, Z_NULL, 0);
  std::array<char, 1 << 16> in_{};
  std::array<char, 1 << 16> out_{};
};

class ZipEntryStream : public EntryStream {
 public:
  ZipEntryStream(std::unique_ptr<std::istream> src, const Entry& e) : buf_(std::move(src), e), in_(&buf_) {}
  std::istream& stream() override { return in_; }
  std::string error() const override { return buf_.error(); }
  std::uint64_t consumed() const override { return buf_.consumed(); }

 private:
  InflateBuf buf_;
  std::istream in_;
};

class ZipContainer : public Container {
 public:
  ZipContainer(std::unique_ptr<Bytes> bytes, std::string name) : Container(std::move(name)), bytes_(std::move(bytes)) {
    read_directory();
  }
  std::unique_ptr<EntryStream> open(const Entry& e) const override {
    if (e.method == kEncrypted) throw IoError(where(e), 0, "encrypted zip entry: not supported");
    if (e.method != 0 && e.method != 8)
      throw IoError(where(e), 0, "zip compression method " + std::to_string(e.method) + " not supported (only stored and deflate)");
    unsigned char lh[30];
    if (!bytes_->read(e.local_offset, lh, sizeof lh) || u32(lh) != 0x04034b50)
      throw IoError(where(e), 0, "no local file header at offset " + std::to_string(e.local_offset) + " (corrupt zip)");
    const std::uint64_t data = e.local_offset + 30 + u16(lh + 26) + u16(lh + 28);
    if (data > bytes_->size() || e.comp_size > bytes_->size() - data)
      throw IoError(where(e), 0, "entry data runs past the end of the archive (truncated zip?)");
    return std::make_unique<ZipEntryStream>(bytes_->stream_at(data), e);
  }
  std::string where(const Entry& e) const override { return name_ + ":" + e.path; }

 private:
  [[noreturn]] void bad(const std::string& why) const { throw IoError(name_, 0, "not a readable zip archive: " + why); }

  void read_directory() {
    const std::uint64_t size = bytes_->size();
    if (size < 22) bad("shorter than an end-of-central-directory record");
    const std::size_t tail = static_cast<std::size_t>(std::min<std::uint64_t>(size, 22 + 65535));
    std::string buf(tail, '\0');
    if (!bytes_->read(size - tail, buf.data(), tail)) bad("read error");
    std::size_t eocd = std::string::npos;
    for (std::size_t i = tail - 22 + 1; i-- > 0;) {
      const auto* p = reinterpret_cast<const unsigned char*>(buf.data() + i);
      if (u32(p) == 0x06054b50) { eocd = i; break; }
    }
    if (eocd == std::string::npos) bad("no end-of-central-directory record (truncated or not a zip)");
    const auto* e = reinterpret_cast<const unsigned char*>(buf.data() + eocd);
    std::uint64_t count = u16(e + 10), cd_size = u32(e + 12), cd_off = u32(e + 16);
    const std::uint64_t eocd_abs = size - tail + eocd;
    if ((count == 0xFFFF || cd_size == 0xFFFFFFFFu || cd_off == 0xFFFFFFFFu) && eocd_abs >= 20) {
      unsigned char loc[20];
      if (bytes_->read(eocd_abs - 20, loc, 20) && u32(loc) == 0x07064b50) {
        unsigned char z64[56];
        if (!bytes_->read(u64(loc + 8), z64, 56) || u32(z64) != 0x06064b50) bad("zip64 end record missing");
        count = u64(z64 + 32);
        cd_size = u64(z64 + 40);
        cd_off = u64(z64 + 48);
      }
    }
    if (cd_off > size || cd_size > size - cd_off) bad("central directory outside the file (truncated?)");
    if (count > cd_size / 46) bad("central directory too small for " + std::to_string(count) + " entries");
    std::string cd(static_cast<std::size_t>(cd_size), '\0');
    if (!bytes_->read(cd_off, cd.data(), cd.size())) bad("read error");
    std::size_t pos = 0;
    for (std::uint64_t i = 0; i < count; ++i) {
      if (pos + 46 > cd.size()) bad("central directory entry " + std::to_string(i) + " truncated");
      const auto* c = reinterpret_cast<const unsigned char*>(cd.data() + pos);
      if (u32(c) != 0x02014b50) bad("bad central directory signature at entry " + std::to_string(i));
      const std::uint16_t flags = u16(c + 8), method = u16(c + 10);
      Entry en;
      en.crc32 = u32(c + 16);
      en.comp_size = u32(c + 20);
      en.size = u32(c + 24);
      const std::size_t nlen = u16(c + 28), xlen = u16(c + 30), klen = u16(c + 32);
      en.local_offset = u32(c + 42);
      if (pos + 46 + nlen + xlen + klen > cd.size()) bad("central directory entry " + std::to_string(i) + " truncated");
      en.path = cd.substr(pos + 46, nlen);
      // zip64 extra field: the 0xFFFFFFFF fields, in order
      for (std::size_t x = pos + 46 + nlen; x + 4 <= pos + 46 + nlen + xlen;) {
        const auto* xp = reinterpret_cast<const unsigned char*>(cd.data() + x);
        const std::size_t id = u16(xp), len = u16(xp + 2);
        if (x + 4 + len > pos + 46 + nlen + xlen) break;
        if (id == 0x0001) {
          std::size_t k = 0;
          auto take = [&](std::uint64_t& field, bool wanted) {
            if (wanted && k + 8 <= len) { field = u64(xp + 4 + k); k += 8; }
          };
          take(en.size, en.size == 0xFFFFFFFFu);
          take(en.comp_size, en.comp_size == 0xFFFFFFFFu);
          take(en.local_offset, en.local_offset == 0xFFFFFFFFu);
        }
        x += 4 + len;
      }
      pos += 46 + nlen + xlen + klen;
      std::replace(en.path.begin(), en.path.end(), '\\', '/');
      if (en.path.empty() || en.path.back() == '/') continue;  // a folder
      en.method = (flags & 1u) ? kEncrypted : method;
      en.base = base_of(en.path);
      if (en.base.rfind("._", 0) == 0 || en.path.rfind("__MACOSX/", 0) == 0) continue;  // macOS resource forks
      entries_.push_back(std::move(en));
    }
  }

  std::unique_ptr<Bytes> bytes_;
};

class FolderContainer : public Container {
 public:
  /// only_file: a container of that one file of the folder.
  explicit FolderContainer(const std::string& dir, const std::string& only_file = "") : Container(dir) {
    namespace fs = std::filesystem;
    if (!only_file.empty()) {
      std::error_code ec;
      Entry e;
      e.path = e.base = only_file;
      e.size = fs::file_size(fs::path(dir) / only_file, ec);
      if (ec) e.size = 0;
      entries_.push_back(std::move(e));
      return;
    }
    std::error_code ec;
    std::vector<std::pair<fs::path, int>> todo{{fs::path(dir), 0}};
    while (!todo.empty()) {
      const auto [d, depth] = todo.back();
      todo.pop_back();
      for (fs::directory_iterator it(d, ec), end; !ec && it != end; it.increment(ec)) {
        const fs::path p = it->path();
        if (it->is_directory(ec)) {
          if (depth < 2) todo.emplace_back(p, depth + 1);
          continue;
        }
        if (!it->is_regular_file(ec)) continue;
        Entry e;
        e.path = fs::relative(p, dir, ec).generic_string();
        e.base = p.filename().string();
        e.size = it->file_size(ec);
        if (ec) { ec.clear(); e.size = 0; }
        entries_.push_back(std::move(e));
      }
      ec.clear();
    }
    std::sort(entries_.begin(), entries_.end(), [](const Entry& a, const Entry& b) { return a.path < b.path; });
  }
  std::unique_ptr<EntryStream> open(const Entry& e) const override {
    const std::string full = (std::filesystem::path(name_) / e.path).string();
    auto f = std::make_unique<std::ifstream>(full, std::ios::binary);
    if (!*f) throw IoError(full, 0, std::string("cannot open: ") + std::strerror(errno));
    return std::make_unique<PlainEntryStream>(std::move(f));
  }
  std::string where(const Entry& e) const override { return (std::filesystem::path(name_) / e.path).string(); }
};

class MemoryContainer : public Container {
 public:
  MemoryContainer(std::vector<std::pair<std::string, std::string>> files, std::string name) : Container(std::move(name)) {
    for (auto& [path, bytes] : files) {
      Entry e;
      e.path = path;
      e.base = base_of(path);
      e.size = bytes.size();
      entries_.push_back(e);
      data_[path] = std::make_shared<const std::string>(std::move(bytes));
    }
  }
  std::unique_ptr<EntryStream> open(const Entry& e) const override {
    auto it = data_.find(e.path);
    if (it == data_.end()) throw IoError(where(e), 0, "cannot open: no such file");
    return std::make_unique<PlainEntryStream>(std::make_unique<SharedStringStream>(it->second, 0));
  }
  std::string where(const Entry& e) const override { return name_ + "/" + e.path; }

 private:
  std::map<std::string, std::shared_ptr<const std::string>> data_;
};

}  // namespace

std::uint64_t Container::total_bytes() const {
  std::uint64_t n = 0;
  for (const Entry& e : entries_) n += e.comp_size > 0 ? e.comp_size : e.size;
  return n;
}

const Entry* Container::find(const std::string& base) const {
  const std::string want = lower(base);
  const Entry* best = nullptr;
  for (const Entry& e : entries_) {
    if (lower(e.base) != want) continue;
    if (!best || std::count(e.path.begin(), e.path.end(), '/') < std::count(best->path.begin(), best->path.end(), '/'))
      best = &e;
  }
  return best;
}

std::string Container::root() const {
  std::map<std::string, int> n;
  for (const Entry& e : entries_) ++n[dir_of(e.path)];
  std::string best;
  int most = -1;
  for (const auto& [d, k] : n)
    if (k > most) { best = d; most = k; }
  return best;
}

const Entry* Container::find_path(const std::string& rel) const {
  const std::string r = root();
  const std::string want = lower(r.empty() ? rel : r + "/" + rel);
  for (const Entry& e : entries_)
    if (lower(e.path) == want) return &e;
  return nullptr;
}

std::unique_ptr<Container> open_folder(const std::string& dir) { return std::make_unique<FolderContainer>(dir); }

std::unique_ptr<Container> open_single_file(const std::string& path) {
  const std::filesystem::path p(path);
  return std::make_unique<FolderContainer>(p.parent_path().empty() ? "." : p.parent_path().string(), p.filename().string());
}

std::unique_ptr<Container> open_zip_file(const std::string& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw IoError(path, 0, "cannot open: " + ec.message());
  return std::make_unique<ZipContainer>(std::make_unique<FileBytes>(path, size), path);
}

std::unique_ptr<Container> open_zip_bytes(std::string bytes, std::string name) {
  return std::make_unique<ZipContainer>(std::make_unique<StringBytes>(std::move(bytes)), std::move(name));
}

std::unique_ptr<Container> open_memory_files(std::vector<std::pair<std::string, std::string>> files, std::string name) {
  return std::make_unique<MemoryContainer>(std::move(files), std::move(name));
}

bool looks_like_zip(const std::string& b) {
  return b.size() >= 4 && b[0] == 'P' && b[1] == 'K' &&
         ((b[2] == 3 && b[3] == 4) || (b[2] == 5 && b[3] == 6));
}

}  // namespace pdnav::io::detail
