// GPS L1 C/A LNAV word/subframe decoding (IS-GPS-200 20.3.2, 20.3.5 parity).
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pdnav/gnss/ephemeris.h"

namespace pdnav::gnss {

/// One parity-checked subframe: the 24 source data bits of each of the 10 words.
struct LnavSubframe {
  std::array<std::uint32_t, 10> words{};
  int subframe_id = 0;  // from the HOW
  int tow_count = 0;    // truncated TOW count of the next subframe (x 6 s)
  /// `len` bits starting at bit `start` (1-based, IS-GPS-200 numbering) of word `word` (1-based).
  std::uint32_t bits(int word, int start, int len) const;
};

/// Six parity bits D25..D30 of a word from its source bits d1..d24 and D29*, D30*.
std::uint32_t lnav_parity(std::uint32_t data24, int d29_star, int d30_star);

/// Decode 40 Android bytes; nullopt + reason ("bad length", "parity", "bad preamble").
std::optional<LnavSubframe> decode_lnav_subframe(const std::vector<std::uint8_t>& data, std::string* why_not);

/// Subframes 1-3 of one PRN to an ephemeris (10-bit week resolved against reference_full_week).
KeplerEphemeris lnav_to_ephemeris(int prn, const LnavSubframe& s1, const LnavSubframe& s2, const LnavSubframe& s3,
                                  int reference_full_week);

}  // namespace pdnav::gnss
