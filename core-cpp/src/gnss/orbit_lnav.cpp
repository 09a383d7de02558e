// GPS L1 C/A LNAV subframes 1-3 -> broadcast ephemeris (IS-GPS-200 20.3.2 - 20.3.3.4,
// parity algorithm Table 20-XIV, scale factors Tables 20-I and 20-III).
// Android GnssNavigationMessage TYPE_GPS_L1CA: 40 bytes = 10 words, each 30 bits
// right-aligned in 32 bits, most significant byte first.
#include <cmath>

#include "pdnav/geo/time.h"
#include "pdnav/gnss/ephemeris.h"
#include "pdnav/gnss/orbit_lnav.h"

namespace pdnav::gnss {
namespace {

constexpr double kGpsPi = 3.1415926535898;  // IS-GPS-200 value for semicircles

std::uint32_t raw_word(const std::vector<std::uint8_t>& d, int w) {
  const std::size_t i = static_cast<std::size_t>(w) * 4;
  return ((std::uint32_t{d[i]} << 24) | (std::uint32_t{d[i + 1]} << 16) | (std::uint32_t{d[i + 2]} << 8) |
          std::uint32_t{d[i + 3]}) & 0x3FFFFFFFu;
}

int bit(std::uint32_t word30, int n) { return static_cast<int>((word30 >> (30 - n)) & 1u); }  // n = 1..30

}  // namespace

std::uint32_t lnav_parity(std::uint32_t data24, int d29_star, int d30_star) {
  // data24 holds source bits d1..d24 (d1 = MSB); IS-GPS-200 Table 20-XIV.
  auto d = [&](int n) { return static_cast<int>((data24 >> (24 - n)) & 1u); };
  auto x = [&](std::initializer_list<int> idx) {
    int v = 0;
    for (int i : idx) v ^= d(i);
    return v;
  };
  const int p25 = d29_star ^ x({1, 2, 3, 5, 6, 10, 11, 12, 13, 14, 17, 18, 20, 23});
  const int p26 = d30_star ^ x({2, 3, 4, 6, 7, 11, 12, 13, 14, 15, 18, 19, 21, 24});
  const int p27 = d29_star ^ x({1, 3, 4, 5, 7, 8, 12, 13, 14, 15, 16, 19, 20, 22});
  const int p28 = d30_star ^ x({2, 4, 5, 6, 8, 9, 13, 14, 15, 16, 17, 20, 21, 23});
  const int p29 = d30_star ^ x({1, 3, 5, 6, 7, 9, 10, 14, 15, 16, 17, 18, 21, 22, 24});
  const int p30 = d29_star ^ x({3, 5, 6, 8, 9, 10, 11, 13, 15, 19, 22, 23, 24});
  return static_cast<std::uint32_t>((p25 << 5) | (p26 << 4) | (p27 << 3) | (p28 << 2) | (p29 << 1) | p30);
}

std::optional<LnavSubframe> decode_lnav_subframe(const std::vector<std::uint8_t>& data, std::string* why_not) {
  auto fail = [&](const char* r) -> std::optional<LnavSubframe> {
    if (why_not) *why_not = r;
    return std::nullopt;
  };
  if (data.size() < 40) return fail("bad length");
  LnavSubframe sf;
  int d29 = 0, d30 = 0;  // word 10 of the previous subframe ends in 00 (IS-GPS-200 20.3.5.2)
  for (int w = 0; w < 10; ++w) {
    const std::uint32_t word = raw_word(data, w);
    std::uint32_t d24 = word >> 6;
    if (d30) d24 ^= 0xFFFFFFu;  // transmitted bits are inverted when D30* = 1
    if (lnav_parity(d24, d29, d30) != (word & 0x3Fu)) return fail("parity");
    sf.words[static_cast<std::size_t>(w)] = d24;
    d29 = bit(word, 29);
    d30 = bit(word, 30);
  }
  if ((sf.words[0] >> 16) != 0x8B) return fail("bad preamble");
  sf.subframe_id = static_cast<int>((sf.words[1] >> 2) & 0x7u);
  sf.tow_count = static_cast<int>(sf.words[1] >> 7);
  return sf;
}

std::uint32_t LnavSubframe::bits(int word, int start, int len) const {
  return (words[static_cast<std::size_t>(word - 1)] >> (24 - (start - 1) - len)) & ((1u << len) - 1u);
}

namespace {
double as_signed(std::uint64_t v, int len) {
  const std::uint64_t sign = std::uint64_t{1} << (len - 1);
  return (v & sign) ? static_cast<double>(static_cast<std::int64_t>(v) - static_cast<std::int64_t>(sign << 1))
                    : static_cast<double>(v);
}
std::uint64_t join(const LnavSubframe& s, int w_hi, int start_hi, int len_hi, int w_lo) {
  return (std::uint64_t{s.bits(w_hi, start_hi, len_hi)} << 24) | s.bits(w_lo, 1, 24);
}
}  // namespace

KeplerEphemeris lnav_to_ephemeris(int prn, const LnavSubframe& s1, const LnavSubframe& s2, const LnavSubframe& s3,
                                  int reference_full_week) {
  KeplerEphemeris k;
  k.sat = SatId{Constellation::kGps, prn};
  const int week = geo::resolve_week_rollover(static_cast<int>(s1.bits(3, 1, 10)), reference_full_week);
  k.accuracy_m = s1.bits(3, 13, 4);  // URA index
  k.health = s1.bits(3, 17, 6);
  k.group_delay_s = as_signed(s1.bits(7, 17, 8), 8) * std::ldexp(1.0, -31);
  const double toc_sow = s1.bits(8, 9, 16) * 16.0;
  k.af2_sps2 = as_signed(s1.bits(9, 1, 8), 8) * std::ldexp(1.0, -55);
  k.af1_sps = as_signed(s1.bits(9, 9, 16), 16) * std::ldexp(1.0, -43);
  k.af0_s = as_signed(s1.bits(10, 1, 22), 22) * std::ldexp(1.0, -31);

  k.iode = static_cast<int>(s2.bits(3, 1, 8));
  k.crs_m = as_signed(s2.bits(3, 9, 16), 16) * std::ldexp(1.0, -5);
  k.delta_n_radps = as_signed(s2.bits(4, 1, 16), 16) * std::ldexp(1.0, -43) * kGpsPi;
  k.m0_rad = as_signed(join(s2, 4, 17, 8, 5), 32) * std::ldexp(1.0, -31) * kGpsPi;
  k.cuc_rad = as_signed(s2.bits(6, 1, 16), 16) * std::ldexp(1.0, -29);
  k.e = static_cast<double>(join(s2, 6, 17, 8, 7)) * std::ldexp(1.0, -33);
  k.cus_rad = as_signed(s2.bits(8, 1, 16), 16) * std::ldexp(1.0, -29);
  k.sqrt_a_sqrtm = static_cast<double>(join(s2, 8, 17, 8, 9)) * std::ldexp(1.0, -19);
  const double toe_sow = s2.bits(10, 1, 16) * 16.0;

  k.cic_rad = as_signed(s3.bits(3, 1, 16), 16) * std::ldexp(1.0, -29);
  k.omega0_rad = as_signed(join(s3, 3, 17, 8, 4), 32) * std::ldexp(1.0, -31) * kGpsPi;
  k.cis_rad = as_signed(s3.bits(5, 1, 16), 16) * std::ldexp(1.0, -29);
  k.i0_rad = as_signed(join(s3, 5, 17, 8, 6), 32) * std::ldexp(1.0, -31) * kGpsPi;
  k.crc_m = as_signed(s3.bits(7, 1, 16), 16) * std::ldexp(1.0, -5);
  k.omega_rad = as_signed(join(s3, 7, 17, 8, 8), 32) * std::ldexp(1.0, -31) * kGpsPi;
  k.omega_dot_radps = as_signed(s3.bits(9, 1, 24), 24) * std::ldexp(1.0, -43) * kGpsPi;
  k.idot_radps = as_signed(s3.bits(10, 9, 14), 14) * std::ldexp(1.0, -43) * kGpsPi;

  const double toc_s = static_cast<double>(week) * geo::kSecondsPerWeek + toc_sow;
  k.toc_gps_ns = static_cast<TimeNs>(std::llround(toc_s * 1e9));
  k.toe_gps_ns = static_cast<TimeNs>(std::llround((toc_s + geo::wrap_week_s(toe_sow - toc_sow)) * 1e9));
  return k;
}

bool EphemerisStore::add_gps_lnav_subframe(int svid, int subframe_id, const std::vector<std::uint8_t>& data,
                                           int reference_full_week, std::string* why_not) {
  auto fail = [&](const char* r) {
    if (why_not) *why_not = r;
    return false;
  };
  if (why_not) why_not->clear();
  if (svid < 1 || svid > 32) return fail("bad svid");
  if (subframe_id < 1 || subframe_id > 5) return fail("bad subframe id");
  const auto sf = decode_lnav_subframe(data, why_not);
  if (!sf) return false;
  if (sf->subframe_id != subframe_id) return fail("subframe id mismatch");
  if (subframe_id > 3) return false;  // almanac / ionosphere pages: not used
  LnavBuffer& buf = lnav_[svid];
  buf.sub[static_cast<std::size_t>(subframe_id - 1)] = data;
  for (const auto& s : buf.sub)
    if (s.empty()) return false;
  const auto s1 = decode_lnav_subframe(buf.sub[0], nullptr);
  const auto s2 = decode_lnav_subframe(buf.sub[1], nullptr);
  const auto s3 = decode_lnav_subframe(buf.sub[2], nullptr);
  const std::uint32_t iodc_lsb = s1->bits(8, 1, 8);
  if (iodc_lsb != s2->bits(3, 1, 8) || iodc_lsb != s3->bits(10, 1, 8)) return false;  // data set cut-over
  const KeplerEphemeris k = lnav_to_ephemeris(svid, *s1, *s2, *s3, reference_full_week);
  if (!(k.sqrt_a_sqrtm > 2000.0 && k.e < 0.5)) return fail("implausible orbit");
  add(k);
  buf = LnavBuffer{};
  return true;
}

bool EphemerisStore::add_nav_message(const NavMessageSample& msg, int reference_full_week, std::string* why_not) {
  constexpr int kTypeGpsL1ca = 0x0101;  // android.location.GnssNavigationMessage.TYPE_GPS_L1CA
  if (msg.type != kTypeGpsL1ca) {
    if (why_not) *why_not = "unsupported type";
    return false;
  }
  return add_gps_lnav_subframe(msg.svid, msg.sub_message_id, msg.data, reference_full_week, why_not);
}

}  // namespace pdnav::gnss
