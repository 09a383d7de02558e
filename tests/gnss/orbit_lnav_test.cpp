// GPS LNAV subframes (Android GnssNavigationMessage TYPE_GPS_L1CA) -> ephemeris.
// No real Nav rows are available, so a real RINEX ephemeris (G01, 2023-03-14) is encoded
// into subframes 1-3 by an independent encoder below (IS-GPS-200 20.3.3.3/20.3.3.4 layout,
// parity with the Table 20-XIV hex masks) and must decode to the same orbit.
#include <bitset>
#include <cmath>

#include <gtest/gtest.h>

#include "pdnav/geo/time.h"
#include "pdnav/gnss/ephemeris.h"
#include "pdnav/gnss/orbit_lnav.h"
#include "pdnav/gnss/rinex.h"
#include "test_data.h"

namespace pdnav::gnss {
namespace {

constexpr double kSc = 3.1415926535898;  // semicircle -> rad
constexpr std::uint32_t kMasks[6] = {0xEC7CD2, 0x763E69, 0xBB1F34, 0x5D8F9A, 0xAEC7CD, 0x2DEA27};

int popcount_parity(std::uint32_t v) { return static_cast<int>(std::bitset<32>(v).count() & 1u); }

struct Subframe {
  std::array<std::uint32_t, 10> d{};  // 24 source bits per word
  void put(int word, int start, int len, std::int64_t value) {
    const std::uint32_t v = static_cast<std::uint32_t>(value) & ((1u << len) - 1u);
    d[static_cast<std::size_t>(word - 1)] |= v << (24 - (start - 1) - len);
  }
  void put_split(int word, int len_total, std::int64_t value) {  // 8 MSBs at bits 17-24, 24 LSBs next word
    const auto u = static_cast<std::uint64_t>(value) & ((std::uint64_t{1} << len_total) - 1);
    put(word, 17, 8, static_cast<std::int64_t>(u >> 24));
    put(word + 1, 1, 24, static_cast<std::int64_t>(u & 0xFFFFFF));
  }
};

std::uint32_t parity6(std::uint32_t d, int d29, int d30) {
  const int star[6] = {d29, d30, d29, d30, d30, d29};
  std::uint32_t p = 0;
  for (int i = 0; i < 6; ++i) p = (p << 1) | static_cast<std::uint32_t>(popcount_parity(d & kMasks[i]) ^ star[i]);
  return p;
}

/// Transmit a subframe: parity, inversion after D30* = 1, and 't' bits that zero D29/D30
/// of words 2 and 10. Output: Android's 40 bytes.
std::vector<std::uint8_t> transmit(Subframe sf) {
  std::vector<std::uint8_t> out;
  int d29 = 0, d30 = 0;
  for (std::size_t w = 0; w < 10; ++w) {
    if (w == 1 || w == 9) {
      for (std::uint32_t t = 0; t < 4; ++t) {
        const std::uint32_t cand = (sf.d[w] & ~3u) | t;
        if ((parity6(cand, d29, d30) & 3u) == 0) { sf.d[w] = cand; break; }
      }
    }
    const std::uint32_t tx = (d30 ? ~sf.d[w] : sf.d[w]) & 0xFFFFFF;
    const std::uint32_t p = parity6(sf.d[w], d29, d30);
    const std::uint32_t word = (tx << 6) | p;
    for (int b = 3; b >= 0; --b) out.push_back(static_cast<std::uint8_t>(word >> (8 * b)));
    d29 = static_cast<int>((p >> 1) & 1u);
    d30 = static_cast<int>(p & 1u);
  }
  return out;
}

std::int64_t q(double v, int pow2) { return std::llround(std::ldexp(v, -pow2)); }

std::array<std::vector<std::uint8_t>, 3> encode(const KeplerEphemeris& k) {
  const auto toc = geo::gps_ns_to_week_tow(k.toc_gps_ns);
  const auto toe = geo::gps_ns_to_week_tow(k.toe_gps_ns);
  std::array<Subframe, 3> s;
  for (int i = 0; i < 3; ++i) {
    s[i].put(1, 1, 8, 0x8B);
    s[i].put(2, 1, 17, 1000 + i);
    s[i].put(2, 20, 3, i + 1);
  }
  s[0].put(3, 1, 10, toc.week % 1024);
  s[0].put(3, 17, 6, static_cast<std::int64_t>(k.health));
  s[0].put(3, 23, 2, k.iode >> 8);
  s[0].put(7, 17, 8, q(k.group_delay_s, -31));
  s[0].put(8, 1, 8, k.iode & 0xFF);
  s[0].put(8, 9, 16, q(toc.tow_s, 4));
  s[0].put(9, 1, 8, q(k.af2_sps2, -55));
  s[0].put(9, 9, 16, q(k.af1_sps, -43));
  s[0].put(10, 1, 22, q(k.af0_s, -31));
  s[1].put(3, 1, 8, k.iode);
  s[1].put(3, 9, 16, q(k.crs_m, -5));
  s[1].put(4, 1, 16, q(k.delta_n_radps / kSc, -43));
  s[1].put_split(4, 32, q(k.m0_rad / kSc, -31));
  s[1].put(6, 1, 16, q(k.cuc_rad, -29));
  s[1].put_split(6, 32, q(k.e, -33));
  s[1].put(8, 1, 16, q(k.cus_rad, -29));
  s[1].put_split(8, 32, q(k.sqrt_a_sqrtm, -19));
  s[1].put(10, 1, 16, q(toe.tow_s, 4));
  s[2].put(3, 1, 16, q(k.cic_rad, -29));
  s[2].put_split(3, 32, q(k.omega0_rad / kSc, -31));
  s[2].put(5, 1, 16, q(k.cis_rad, -29));
  s[2].put_split(5, 32, q(k.i0_rad / kSc, -31));
  s[2].put(7, 1, 16, q(k.crc_m, -5));
  s[2].put_split(7, 32, q(k.omega_rad / kSc, -31));
  s[2].put(9, 1, 24, q(k.omega_dot_radps / kSc, -43));
  s[2].put(10, 1, 8, k.iode);
  s[2].put(10, 9, 14, q(k.idot_radps / kSc, -43));
  return {transmit(s[0]), transmit(s[1]), transmit(s[2])};
}

KeplerEphemeris g01() {
  const RinexNavData nav = read_rinex_nav_file(test::shared_data("gnss-orbits-2023-073/BRDM00DLR_S_20230730000_01D_MN.rnx"));
  return nav.kepler.front();
}

TEST(OrbitLnav, ParityMatchesTableMasks) {
  for (std::uint32_t d : {0x000000u, 0xFFFFFFu, 0x8B0000u, 0x123456u, 0xABCDEFu})
    for (int s = 0; s < 4; ++s) EXPECT_EQ(lnav_parity(d, s >> 1, s & 1), parity6(d, s >> 1, s & 1)) << std::hex << d;
}

TEST(OrbitLnav, EncodedRealEphemerisDecodesToTheSameOrbit) {
  const KeplerEphemeris k = g01();
  ASSERT_EQ(k.sat.to_string(), "G01");
  const auto frames = encode(k);
  EphemerisStore store;
  std::string why;
  const int week = geo::gps_ns_to_week_tow(k.toe_gps_ns).week;
  EXPECT_FALSE(store.add_gps_lnav_subframe(1, 1, frames[0], week + 300, &why));
  EXPECT_EQ(why, "");
  EXPECT_FALSE(store.add_gps_lnav_subframe(1, 2, frames[1], week + 300, &why));
  EXPECT_TRUE(store.add_gps_lnav_subframe(1, 3, frames[2], week + 300, &why)) << why;  // 10-bit week resolved
  ASSERT_EQ(store.size(), 1u);
  for (int dt_min = -120; dt_min <= 120; dt_min += 30) {
    const TimeNs t = k.toe_gps_ns + dt_min * 60 * kNsPerS;
    const auto s = store.state(SatId{Constellation::kGps, 1}, t, &why);
    ASSERT_TRUE(s) << why;
    const SatState ref = kepler_state(k, t);
    EXPECT_LT((s->pos.p_m - ref.pos.p_m).norm(), 0.1);  // quantisation only (2^-31 semicircles ~ 4 cm)
    EXPECT_NEAR(s->clock_bias_s, ref.clock_bias_s, 1e-9);
    EXPECT_NEAR(s->group_delay_s, ref.group_delay_s, 1e-12);
  }
}

TEST(OrbitLnav, BadSubframesAreRefusedWithAReason) {
  const auto frames = encode(g01());
  EphemerisStore store;
  std::string why;
  std::vector<std::uint8_t> shortened(frames[0].begin(), frames[0].end() - 1);
  EXPECT_FALSE(store.add_gps_lnav_subframe(1, 1, shortened, 2253, &why));
  EXPECT_EQ(why, "bad length");
  auto flipped = frames[1];
  flipped[21] ^= 0x10;
  EXPECT_FALSE(store.add_gps_lnav_subframe(1, 2, flipped, 2253, &why));
  EXPECT_EQ(why, "parity");
  EXPECT_FALSE(store.add_gps_lnav_subframe(1, 3, frames[1], 2253, &why));
  EXPECT_EQ(why, "subframe id mismatch");
  EXPECT_FALSE(store.add_gps_lnav_subframe(40, 1, frames[0], 2253, &why));
  EXPECT_EQ(why, "bad svid");
  // Subframes of two different data sets (IODE mismatch) never combine.
  KeplerEphemeris other = g01();
  other.iode = 13;
  const auto frames2 = encode(other);
  EXPECT_FALSE(store.add_gps_lnav_subframe(1, 1, frames[0], 2253, &why));
  EXPECT_FALSE(store.add_gps_lnav_subframe(1, 2, frames2[1], 2253, &why));
  EXPECT_FALSE(store.add_gps_lnav_subframe(1, 3, frames[2], 2253, &why));
  EXPECT_EQ(store.size(), 0u);
  EXPECT_TRUE(store.add_gps_lnav_subframe(1, 2, frames[1], 2253, &why));
}

}  // namespace
}  // namespace pdnav::gnss

namespace pdnav::gnss {
namespace {

TEST(OrbitLnav, NavMessageSamplesOfGpsL1caAreDecodedOthersRefused) {
  const auto frames = encode(g01());
  EphemerisStore store;
  std::string why;
  NavMessageSample m;
  m.svid = 1;
  m.type = 0x0101;
  for (int i = 0; i < 3; ++i) {
    m.sub_message_id = i + 1;
    m.data = frames[static_cast<std::size_t>(i)];
    EXPECT_EQ(store.add_nav_message(m, 2253, &why), i == 2) << why;
  }
  EXPECT_EQ(store.size(), 1u);
  m.type = 0x0301;  // GLONASS L1 C/A strings: not decoded
  EXPECT_FALSE(store.add_nav_message(m, 2253, &why));
  EXPECT_EQ(why, "unsupported type");
}

}  // namespace
}  // namespace pdnav::gnss
