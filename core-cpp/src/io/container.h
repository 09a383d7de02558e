// A recording made of several files: a folder, a zip archive (zlib inflate, streamed), or
// files held in memory (tests, fuzzers). Each entry opens as its own stream, so a reader can
// keep one cursor per file open at once (k-way merge) with constant memory per file.
#pragma once
#include <cstdint>
#include <istream>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace pdnav::io::detail {

struct Entry {
  std::string path;      // inside the container, '/'-separated ("2023-03-17/Gyroscope.csv")
  std::string base;      // last path component ("Gyroscope.csv")
  std::uint64_t size = 0;  // uncompressed bytes
  // zip only
  std::uint64_t local_offset = 0, comp_size = 0;
  std::uint32_t crc32 = 0;
  int method = 0;
};

/// One open entry. error() is non-empty when the stream ended because of a problem
/// (corrupt deflate data, CRC or size mismatch, read error).
class EntryStream {
 public:
  virtual ~EntryStream() = default;
  virtual std::istream& stream() = 0;
  virtual std::string error() const { return {}; }
  /// Bytes of the container consumed so far (compressed bytes for a zip entry).
  virtual std::uint64_t consumed() const = 0;
};

class Container {
 public:
  virtual ~Container() = default;
  const std::string& name() const { return name_; }
  const std::vector<Entry>& entries() const { return entries_; }
  /// Opens one entry; throws IoError(where(e), 0, reason).
  virtual std::unique_ptr<EntryStream> open(const Entry& e) const = 0;
  /// How messages name an entry: "folder/Gyroscope.csv" or "walk.zip:Gyroscope.csv".
  virtual std::string where(const Entry& e) const = 0;
  /// Total bytes to read (progress).
  std::uint64_t total_bytes() const;
  /// The entry whose base name equals `base` (case-insensitive), shallowest first; or null.
  const Entry* find(const std::string& base) const;
  /// The entry at `path` relative to the folder holding the recording's files (case-insensitive).
  const Entry* find_path(const std::string& rel) const;
  /// The folder (inside the container) holding the most entries: the recording's root.
  std::string root() const;

 protected:
  explicit Container(std::string name) : name_(std::move(name)) {}
  std::string name_;
  std::vector<Entry> entries_;
};

/// Every regular file under `dir` (two levels deep at most).
std::unique_ptr<Container> open_folder(const std::string& dir);
/// One file of a recording on its own (a single Sensor Logger or phyphox CSV).
std::unique_ptr<Container> open_single_file(const std::string& path);
/// A zip archive on disk. Throws IoError when it is not a complete zip.
std::unique_ptr<Container> open_zip_file(const std::string& path);
/// A zip archive in memory.
std::unique_ptr<Container> open_zip_bytes(std::string bytes, std::string name);
/// Files in memory: (path, bytes).
std::unique_ptr<Container> open_memory_files(std::vector<std::pair<std::string, std::string>> files,
                                             std::string name);
/// True when the first bytes are a zip local-file or end-of-central-directory signature.
bool looks_like_zip(const std::string& first_bytes);

}  // namespace pdnav::io::detail
