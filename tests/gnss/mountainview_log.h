// The real Mountain View GnssLogger log and its broadcast ephemeris (shared data
// gnss-mountainview/), as the GNSS engine tests read them.
#pragma once
#include <memory>
#include <variant>
#include <vector>

#include "pdnav/geo/samples.h"
#include "pdnav/gnss/ephemeris.h"
#include "pdnav/io/log_reader.h"
#include "test_data.h"

namespace pdnav::test {

/// Every Raw row of the log, in file order.
inline std::vector<GnssRawSample> mountainview_raw() {
  std::vector<GnssRawSample> rows;
  io::LogReader reader(shared_data("gnss-mountainview/pseudoranges_log_2016_08_22_14_45_50.txt"));
  Sample s;
  while (reader.next(s))
    if (const auto* raw = std::get_if<GnssRawSample>(&s)) rows.push_back(*raw);
  return rows;
}

/// The GPS broadcast ephemeris of the log's day (RINEX 2 hour2350.16n).
inline std::shared_ptr<const gnss::EphemerisStore> mountainview_nav() {
  auto store = std::make_shared<gnss::EphemerisStore>();
  store->load_rinex_nav(shared_data("gnss-mountainview/hour2350.16n"));
  return store;
}

}  // namespace pdnav::test
