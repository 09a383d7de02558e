// A minimal zip writer for tests (PKWARE APPNOTE 4.3: local headers, central directory, end
// record; deflate through zlib, or stored), so zipped recordings are made from the fixtures
// at test time instead of committing binary archives.
#pragma once
#include <zlib.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace pdnav::test {

inline void put16(std::string& s, std::uint32_t v) {
  s.push_back(static_cast<char>(v & 0xFF));
  s.push_back(static_cast<char>((v >> 8) & 0xFF));
}
inline void put32(std::string& s, std::uint32_t v) {
  put16(s, v & 0xFFFF);
  put16(s, v >> 16);
}

/// Raw deflate (no zlib header), as zip method 8 stores it.
inline std::string raw_deflate(const std::string& in) {
  z_stream z{};
  if (deflateInit2(&z, 6, Z_DEFLATED, -MAX_WBITS, 8, Z_DEFAULT_STRATEGY) != Z_OK) throw std::runtime_error("deflateInit2");
  std::string out(deflateBound(&z, static_cast<uLong>(in.size())) + 16, '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(in.data()));
  z.avail_in = static_cast<uInt>(in.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  const int rc = deflate(&z, Z_FINISH);
  deflateEnd(&z);
  if (rc != Z_STREAM_END) throw std::runtime_error("deflate");
  out.resize(z.total_out);
  return out;
}

/// A zip archive of (path, bytes) entries; deflate = false stores them.
inline std::string make_zip(const std::vector<std::pair<std::string, std::string>>& files, bool deflate = true) {
  std::string zip, cd;
  for (const auto& [name, data] : files) {
    const std::string body = deflate ? raw_deflate(data) : data;
    const auto crc = static_cast<std::uint32_t>(crc32(0L, reinterpret_cast<const Bytef*>(data.data()), static_cast<uInt>(data.size())));
    const auto offset = static_cast<std::uint32_t>(zip.size());
    const std::uint32_t method = deflate ? 8 : 0;
    put32(zip, 0x04034b50); put16(zip, 20); put16(zip, 0); put16(zip, method); put16(zip, 0); put16(zip, 0);
    put32(zip, crc); put32(zip, static_cast<std::uint32_t>(body.size())); put32(zip, static_cast<std::uint32_t>(data.size()));
    put16(zip, static_cast<std::uint32_t>(name.size())); put16(zip, 0);
    zip += name;
    zip += body;
    put32(cd, 0x02014b50); put16(cd, 20); put16(cd, 20); put16(cd, 0); put16(cd, method); put16(cd, 0); put16(cd, 0);
    put32(cd, crc); put32(cd, static_cast<std::uint32_t>(body.size())); put32(cd, static_cast<std::uint32_t>(data.size()));
    put16(cd, static_cast<std::uint32_t>(name.size())); put16(cd, 0); put16(cd, 0); put16(cd, 0); put16(cd, 0);
    put32(cd, 0); put32(cd, offset);
    cd += name;
  }
  const auto cd_offset = static_cast<std::uint32_t>(zip.size());
  zip += cd;
  put32(zip, 0x06054b50); put16(zip, 0); put16(zip, 0);
  put16(zip, static_cast<std::uint32_t>(files.size())); put16(zip, static_cast<std::uint32_t>(files.size()));
  put32(zip, static_cast<std::uint32_t>(cd.size())); put32(zip, cd_offset); put16(zip, 0);
  return zip;
}

}  // namespace pdnav::test
