// Hand-made GnssLogger Raw rows with known answers, for the measurement tests
// (measurements_model, dual_frequency, review_defects).
#pragma once
#include <cstdint>

#include "pdnav/geo/samples.h"

namespace pdnav::test {

/// A Raw row logged at t_ns whose receiver clock reads time_nanos when GPS time is rx_gps_ns
/// (FullBiasNanos = TimeNanos - rx_gps_ns; no sub-nanosecond bias, time offset or clock
/// discontinuity), for satellite svid of the Android constellation with tracking state `state`,
/// C/N0 cn0_dbhz and a 10 ns received-time uncertainty. ReceivedSvTimeNanos, the Doppler, the
/// carrier and the ADR are left for the caller.
inline GnssRawSample raw_row(TimeNs t_ns, std::int64_t time_nanos, std::int64_t rx_gps_ns, int constellation, int svid,
                             std::int64_t state, double cn0_dbhz) {
  GnssRawSample r;
  r.t_ns = t_ns;
  r.time_nanos = time_nanos;
  r.full_bias_nanos = r.time_nanos - rx_gps_ns;
  r.bias_nanos = 0.0;
  r.time_offset_nanos = 0.0;
  r.hardware_clock_discontinuity_count = 0;
  r.constellation_type = constellation;
  r.svid = svid;
  r.state = state;
  r.cn0_dbhz = cn0_dbhz;
  r.received_sv_time_uncertainty_nanos = 10;
  return r;
}

}  // namespace pdnav::test
