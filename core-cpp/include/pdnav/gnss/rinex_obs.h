// RINEX 3.0x observation files: reader and RINEX 3.04 writer (IGS RINEX 3.04, 2018,
// Sec. 5.1 and Tables A1-A3; 3.00-3.05 share the record layout read here).
//
// The reader turns every epoch into Android-style `GnssRawSample` rows (one per satellite
// and signal), so RINEX data goes through exactly the measurement layer of GnssLogger
// `Raw` rows (measurements.h): the receive time becomes TimeNanos with FullBiasNanos = 0,
// the code becomes ReceivedSvTimeNanos (whole ns) + TimeOffsetNanos (the sub-ns rest, so no
// precision is lost), phase (cycles) becomes AccumulatedDeltaRangeMeters, Doppler (Hz)
// becomes PseudorangeRateMetersPerSecond (= -Doppler * wavelength) and C/N0 stays dB-Hz.
// The writer does the inverse from Raw rows; the round trip is lossless to the RINEX
// resolution (1 mm code/Doppler rate, 1 mcycle phase, 1e-3 dB-Hz, 0.1 ns epochs... see
// docs/gnss.md).
#pragma once
#include <cstdint>
#include <istream>
#include <map>
#include <ostream>
#include <string>
#include <vector>

#include "pdnav/geo/samples.h"
#include "pdnav/gnss/types.h"

namespace pdnav::gnss {

/// One signal of one satellite in an epoch. NaN = blank field.
struct RinexSignalObs {
  std::string code;      // RINEX attribute "1C", "5X", ... (band digit + tracking code)
  double pseudorange_m = kNaN;
  double phase_cycles = kNaN;
  double doppler_hz = kNaN;
  double cn0_dbhz = kNaN;
  int phase_lli = 0;     // loss-of-lock indicator of the phase (bit 0: slip, bit 1: half cycle)
};

struct RinexSatObs {
  SatId sat;
  std::vector<RinexSignalObs> signals;
};

struct RinexObsEpoch {
  std::int64_t gps_ns = 0;   // epoch (receive time) in GPS time, ns since the GPS epoch
  int flag = 0;              // 0 ok, 1 power failure before this epoch, 2..5 events, 6 slips
  int clock_discontinuity_count = 0;  // epochs with flag 1 (power failure) so far
  double clock_offset_s = 0.0;        // receiver clock offset field (0 when blank)
  std::vector<RinexSatObs> sats;
};

struct RinexObsHeader {
  double version = 0.0;
  char file_system = 'M';
  std::map<char, std::vector<std::string>> obs_types;  // 'G' -> {"C1C", "L1C", ...}
  std::map<int, int> glonass_channel;                  // slot -> frequency number k
  std::string time_system = "GPS";
  double approx_xyz_m[3] = {0, 0, 0};
  /// Written by RinexObsWriter: the epoch clock offset is the change of Android's
  /// FullBiasNanos + BiasNanos (code on the corrected time, phase/Doppler on the hardware
  /// clock); the reader then restores both fields so the engine sees the log's clock model.
  bool android_clock_offset = false;
};

struct RinexObsReport {
  std::int64_t epochs = 0, satellite_records = 0, signals = 0;
  std::map<std::string, std::int64_t> skipped_by_reason;  // counted skips (bad records)
  std::vector<std::string> issues;                        // first 100 "file:line: reason"
  std::int64_t skipped_total() const;
};

/// True when the first line of `head` is a RINEX observation header ("OBSERVATION DATA"
/// in columns 21-40 with "RINEX VERSION / TYPE" label) -- used for format detection.
bool looks_like_rinex_obs(const std::string& first_line);

/// Streaming reader. The constructor reads the header and throws
/// std::runtime_error("name:line: reason") when it is not a RINEX 3 observation header
/// (RINEX 2 obs is rejected with that reason). next() returns false at the end; bad epoch
/// or satellite records are skipped and counted in report(), never thrown.
class RinexObsReader {
 public:
  RinexObsReader(std::istream& in, std::string name);
  const RinexObsHeader& header() const { return header_; }
  bool next(RinexObsEpoch& out);
  const RinexObsReport& report() const { return report_; }

 private:
  void read_header();
  void skip(const std::string& why);
  bool getline(std::string& l);
  std::istream& in_;
  std::string name_;
  int line_no_ = 0;
  RinexObsHeader header_;
  RinexObsReport report_;
  int discontinuities_ = 0;
};

/// Carrier frequency of a RINEX band digit for a system (RINEX 3.04 Table 2-4 ff.);
/// GLONASS FDMA bands 1 and 2 need the frequency number k. NaN when unknown.
double rinex_band_carrier_hz(Constellation sys, char band, int glonass_channel);

/// Android-style Raw rows for one epoch (see the file comment); `t_ns` of each row is the
/// GPS time of the epoch. Signals without a usable frequency are counted in `skipped`.
std::vector<GnssRawSample> rinex_epoch_to_raw(const RinexObsEpoch& ep, const RinexObsHeader& hdr,
                                              std::map<std::string, std::int64_t>& skipped);

/// RINEX 3.04 writer from Raw rows (GnssLogger / session log). Rows must be fed in time
/// order; rows with the same TimeNanos form one epoch. The header is written by finish()
/// (it needs the observation types present), so the body is buffered.
class RinexObsWriter {
 public:
  explicit RinexObsWriter(std::string program = "pdnav rinex");
  /// Adds one Raw row; returns false with a reason in `why` when the row cannot be written.
  bool add(const GnssRawSample& r, std::string* why);
  /// Writes the header and every epoch. Returns the number of epochs written.
  std::int64_t finish(std::ostream& out);

 private:
  std::string program_;
  std::int64_t last_disc_ = kMissingInt;
  bool have_ref_ = false, epoch_disc_ = false, disc_ = false;
  std::int64_t ref_full_bias_ns_ = 0;  // FullBias and Bias at the first epoch (or the last discontinuity)
  double ref_bias_ns_ = 0.0;
  std::vector<RinexObsEpoch> epochs_;
  std::int64_t current_time_nanos_ = kMissingInt;
  std::map<char, std::vector<std::string>> codes_;  // system -> attributes seen ("1C", "5X")
  std::map<int, int> glonass_channel_;
};

}  // namespace pdnav::gnss
