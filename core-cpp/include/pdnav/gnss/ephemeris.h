// Broadcast ephemerides and satellite states (issue 7, ephemeris half).
//
// TIME SCALE CONTRACT: every TimeNs argument and field in this header is GPS time (GPST),
// nanoseconds since the GPS epoch 1980-01-06 00:00:00 (geo/time.h). The store converts
// internally: BeiDou Time (BDT = GPST - 14 s, BDS-SIS-ICD-B1I 5.1.2) and GLONASS
// (RINEX epochs are UTC, GLONASS ICD 3.3.3: tb in UTC(SU)+3h). Callers never convert.
//
// Orbit models: GPS/QZSS IS-GPS-200 20.3.3.4.3 (Table 20-IV) and IS-QZSS-PNT; Galileo OS SIS
// ICD 5.1.1; BeiDou BDS-SIS-ICD-B1I 5.2.4.12 (MEO/IGSO, and GEO with the -5 deg rotation);
// GLONASS ICD A.3.1.2 (RK4 integration of the broadcast PZ-90 state, glonass.h).
#pragma once
#include <array>
#include <cstdint>
#include <istream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pdnav/geo/frames.h"
#include "pdnav/geo/samples.h"
#include "pdnav/geo/units.h"
#include "pdnav/gnss/atmosphere.h"
#include "pdnav/gnss/clock_file.h"
#include "pdnav/gnss/sp3.h"
#include "pdnav/gnss/types.h"

namespace pdnav::gnss {

/// Satellite state at a GPS-time transmit instant.
struct SatState {
  /// ECEF position of the antenna (broadcast: APC for GPS/QZSS/BDS/GAL, CoM-ish for GLONASS)
  /// at the transmit instant, expressed in the ECEF frame OF THAT INSTANT. The solver applies
  /// the Earth-rotation (Sagnac) correction for the signal travel time itself.
  geo::Ecef pos;
  Eigen::Vector3d vel_mps = Eigen::Vector3d::Zero();  // ECEF velocity (rotating frame)
  /// Satellite clock offset dtsv [s] INCLUDING the relativistic correction
  /// (IS-GPS-200 20.3.3.3.3.1) but EXCLUDING the group delay below. System time of the
  /// satellite = t_sv - clock_bias_s. For GLONASS: -tau_n + gamma_n (t - tb).
  double clock_bias_s = 0.0;
  double clock_drift_sps = 0.0;  // d(dtsv)/dt [s/s], incl. relativistic rate
  /// Broadcast group delay for the single-frequency user [s]: TGD (GPS/QZSS L1 C/A),
  /// BGD(E1,E5b) (Galileo I/NAV) or BGD(E1,E5a) (F/NAV), TGD1 (BeiDou B1I), 0 for GLONASS.
  /// Single-frequency L1/E1/B1 corrected clock = clock_bias_s - group_delay_s.
  double group_delay_s = 0.0;
  int glonass_channel = 0;       // FDMA frequency number k (GLONASS only, -7..+6)
  bool healthy = true;
  TimeNs toe_gps_ns = 0;         // reference time of the ephemeris used (GPS time)
  int iode = 0;                  // issue of data (GPS IODE, GAL IODnav, BDS AODE, GLO tb index)
};

/// Keplerian broadcast ephemeris (GPS/QZSS LNAV, Galileo I/NAV and F/NAV, BeiDou D1/D2).
/// Angles in radians, rates in rad/s (RINEX stores them that way).
struct KeplerEphemeris {
  SatId sat;
  TimeNs toc_gps_ns = 0;   // clock reference time, converted to GPS time
  TimeNs toe_gps_ns = 0;   // ephemeris reference time, converted to GPS time
  double af0_s = 0, af1_sps = 0, af2_sps2 = 0;
  double crs_m = 0, crc_m = 0, cus_rad = 0, cuc_rad = 0, cis_rad = 0, cic_rad = 0;
  double delta_n_radps = 0, m0_rad = 0, e = 0, sqrt_a_sqrtm = 0;
  double omega0_rad = 0, i0_rad = 0, omega_rad = 0, omega_dot_radps = 0, idot_radps = 0;
  double group_delay_s = 0;   // see SatState::group_delay_s
  double health = 0;          // raw health word/flags (0 = healthy)
  double accuracy_m = 0;      // URA / SISA / URA index as in the file
  int iode = 0;
  int data_source = 0;        // Galileo data sources bits (bit 0 I/NAV E1-B, bit 1 F/NAV, bit 9 E1/E5b)
  bool bds_geo = false;       // BeiDou GEO (PRN 1-5 and 59-63): the -5 deg rotation applies
};

/// GLONASS broadcast ephemeris: PZ-90 state at tb plus luni-solar acceleration.
struct GlonassEphemeris {
  SatId sat;
  TimeNs tb_gps_ns = 0;         // reference time tb, converted from UTC to GPS time
  double minus_tau_n_s = 0;     // RINEX "SV clock bias (-TauN)"
  double gamma_n = 0;           // relative frequency bias
  Eigen::Vector3d pos_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d vel_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d acc_mps2 = Eigen::Vector3d::Zero();  // luni-solar acceleration (ECEF)
  int health = 0;               // Bn (0 = healthy)
  int channel = 0;              // frequency number k
};

struct EphemerisLoadReport {
  std::string file;
  std::map<std::string, int> records_by_system;   // "GPS" -> 32, "Galileo" -> ...
  std::map<std::string, int> skipped_by_reason;   // "IRNSS not supported" -> 6, ...
  std::vector<std::string> issues;                // first 100 "file:line: reason"
  int records_total() const;
  int skipped_total() const;
};

/// Why state() returned nothing. reason strings are stable (count them by string):
///   "no ephemeris", "stale ephemeris", "unhealthy", "unsupported constellation",
///   "numerical failure".
struct EphemerisStoreOptions {
  // Max |t - toe| accepted. GPS/GAL: fit interval 4 h (IS-GPS-200 20.3.4.4, ICD 5.1.1);
  // BDS: 1 h update -> 2 h; QZSS: 2 h fit; GLONASS: 30 min update, +-15 min nominal -> 30 min.
  double gps_max_age_s = 4 * 3600.0;
  double galileo_max_age_s = 4 * 3600.0;
  double beidou_max_age_s = 2 * 3600.0;
  double qzss_max_age_s = 2 * 3600.0;
  double glonass_max_age_s = 30 * 60.0;
  bool accept_unhealthy = false;
  // Precise orbits (add_precise): Lagrange interpolation over `precise_points` SP3 epochs
  // (10 points = degree 9, the usual choice for 15-min IGS orbits (Schenewerk 2003); with
  // 5-min products the error is well below 1 mm); clocks by linear interpolation between
  // the two neighbouring epochs (5-min clocks: the IGS/RINEX CLK convention). Used only
  // inside the SP3 span with a full stencil; otherwise the broadcast ephemeris.
  int precise_points = 10;
  bool prefer_precise = true;
  ClockInterpolationOptions precise_clock;  // RINEX clock files (add_precise_clocks): linear, <= 330 s
};

class EphemerisStore {
 public:
  explicit EphemerisStore(EphemerisStoreOptions options = {});

  /// RINEX 2 GPS (.16n), RINEX 2 GLONASS (.16g), RINEX 3.0x (mixed or single system).
  /// Unsupported systems (IRNSS, SBAS) and malformed records are skipped and counted.
  /// Throws std::runtime_error("file:line: reason") on unreadable files / garbage headers.
  /// May be called for several files; records accumulate (duplicates are ignored).
  EphemerisLoadReport load_rinex_nav(const std::string& path);
  EphemerisLoadReport load_rinex_nav(std::istream& in, const std::string& name);

  void add(const KeplerEphemeris& eph);
  void add(const GlonassEphemeris& eph);

  /// Precise orbits and clocks (SP3, e.g. CODE MGEX) for every satellite the file has.
  /// Conventions (docs/gnss-orbits.md): SP3 positions are the centre of mass and are used
  /// as the antenna position (no phase-centre offset; its line-of-sight effect is common to
  /// all satellites to a few cm); the SP3 clock gets the periodic relativistic correction
  /// -2 r.v / c^2 added (SP3 clocks exclude it) and the broadcast group delay (TGD / BGD)
  /// of the same satellite when a broadcast record is loaded, else 0 (the SP3 clock refers
  /// to the ionosphere-free combination). Returns the number of satellites added.
  int add_precise(const Sp3File& sp3);
  bool has_precise() const { return !precise_.empty(); }
  /// Precise satellite clocks from a RINEX clock file (AS records, e.g. 30 s): for every
  /// satellite the file has, precise states take the clock from it (linear interpolation,
  /// options().precise_clock) instead of the SP3 clock column; same conventions as the SP3
  /// clock (relativistic term added here, group delay as above). Outside the file's span or
  /// across a gap that satellite has no precise state ("gap in the precise clock": the
  /// broadcast ephemeris is used). Needs add_precise for the orbits. Returns the number of
  /// satellites with clocks.
  int add_precise_clocks(const ClockFile& clk);

  /// One GnssLogger `Nav` row of GPS L1 C/A (type 0x0101): `svid` (PRN), `subframe_id`
  /// (Sub-messageId, 1..5) and the 40 data bytes (10 words of 30 bits, each in 32 bits,
  /// MSB first, bits 31..30 padding). Subframes 1-3 with matching IODC/IODE form one
  /// ephemeris, added to the store. `reference_full_week` resolves the 10-bit week (the
  /// GPS week of the log, e.g. from FullBiasNanos). Returns true when an ephemeris was
  /// completed; otherwise false (incomplete set is normal), with a reason in *why_not for
  /// bad input ("bad length", "parity", "bad preamble", "unsupported type").
  bool add_gps_lnav_subframe(int svid, int subframe_id, const std::vector<std::uint8_t>& data,
                             int reference_full_week, std::string* why_not = nullptr);
  /// Same for a GnssLogger `Nav` sample: only type 0x0101 (GPS L1 C/A) is used; other types
  /// return false with *why_not = "unsupported type".
  bool add_nav_message(const NavMessageSample& msg, int reference_full_week, std::string* why_not = nullptr);

  /// State of `sat` at the GPS-time transmit instant `gps_transmit_ns`. The ephemeris with
  /// the nearest reference time is used (Galileo: I/NAV preferred over F/NAV). nullopt with
  /// a reason (see EphemerisStoreOptions) when missing, stale or unhealthy.
  std::optional<SatState> state(const SatId& sat, TimeNs gps_transmit_ns,
                                std::string* why_not = nullptr) const;

  /// GPS Klobuchar coefficients from the nav header (RINEX 2 ION ALPHA/BETA, RINEX 3
  /// GPSA/GPSB); nullptr when no file had them.
  const KlobucharParams* klobuchar() const;

  /// GLONASS frequency number of a slot, from any loaded GLONASS ephemeris.
  std::optional<int> glonass_channel(int slot) const;

  std::vector<SatId> satellites() const;      // sorted, unique
  std::size_t size() const;                   // number of ephemeris records
  const EphemerisStoreOptions& options() const { return options_; }

 private:
  struct LnavBuffer {
    std::array<std::vector<std::uint8_t>, 3> sub;  // subframes 1..3, empty when missing
  };
  EphemerisStoreOptions options_;
  std::map<SatId, std::vector<KeplerEphemeris>> kepler_;
  std::map<SatId, std::vector<GlonassEphemeris>> glonass_;
  std::map<int, LnavBuffer> lnav_;
  std::optional<KlobucharParams> klobuchar_;
  struct PreciseTrack {
    std::vector<TimeNs> t;                 // epochs (GPS time, sorted)
    std::vector<Eigen::Vector3d> pos_m;
    std::vector<double> clock_s;           // NaN when the epoch has no clock
  };
  std::map<SatId, PreciseTrack> precise_;
  std::map<SatId, std::vector<ClockSample>> precise_clock_;
  std::optional<SatState> precise_state(const SatId& sat, TimeNs t, std::string* why_not) const;
  std::optional<SatState> broadcast_state(const SatId& sat, TimeNs t, std::string* why_not) const;
};

/// Broadcast Keplerian state at GPS time t (no health/staleness checks).
SatState kepler_state(const KeplerEphemeris& eph, TimeNs gps_ns);
/// Broadcast GLONASS state at GPS time t by RK4 integration from tb (no checks).
SatState glonass_state(const GlonassEphemeris& eph, TimeNs gps_ns);

}  // namespace pdnav::gnss
