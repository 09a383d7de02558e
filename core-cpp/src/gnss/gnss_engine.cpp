#include "pdnav/gnss/gnss_engine.h"

#include <cmath>
#include <utility>

#include "pdnav/geo/time.h"

namespace pdnav::gnss {
namespace {

constexpr int kGpsL1CaNavType = 0x0101;  // android.location.GnssNavigationMessage.TYPE_GPS_L1CA
constexpr double kNominalTravelS = 0.075;

void merge(std::map<std::string, std::int64_t>& into, const std::map<std::string, std::int64_t>& from) {
  for (const auto& [k, v] : from) into[k] += v;
}

/// chi2 / dof of an SPP fit (Teunissen 2003 Sec. 4.3), NaN without redundancy.
double spp_variance_factor(const SppSolution& spp) {
  const int dof = static_cast<int>(spp.used.size()) - 4 - static_cast<int>(spp.isb_m.size() + spp.isb_l5_m.size());
  return dof > 0 ? spp.chi2 / dof : kNaN;
}

}  // namespace

struct GnssEngine::Impl {
  GnssOptions opt;
  std::shared_ptr<const EphemerisStore> eph;
  std::shared_ptr<EphemerisStore> owned;  // copy made when Nav rows arrive
  std::uint64_t seed = 0;

  std::vector<GnssRawSample> pending;
  std::map<std::string, std::int64_t> excluded;
  std::vector<EpochSolution> solutions;
  std::int64_t epochs = 0;

  // previous epoch (TDCP)
  bool has_prev = false;
  std::vector<CarrierObservation> prev_obs;
  GpsTime prev_rx;
  std::int64_t prev_full_bias_nanos = 0;
  double prev_bias_nanos = 0.0;
  std::int64_t prev_hw_disc = kMissingInt;

  RobustKalman kf;
  CodeSmoother smoother;
  bool have_pos = false;
  geo::Ecef last_pos;
  bool have_frame = false;
  geo::LocalFrame frame;
  TimeNs last_t_ns = 0;
  std::int64_t last_gps_ns = 0;
  std::int64_t last_fix_gps_ns = 0;  // receive time of the last SPP fix given to the KF
  int epochs_since_update = 0;
  int last_sats_used = 0;
  bool have_clock_system = false;
  Constellation kf_clock_system = Constellation::kGps;
  SignalBand kf_clock_band = SignalBand::kL1;
  std::string last_reason;

  void count(const std::string& reason, std::int64_t n = 1) { excluded[reason] += n; }

  /// Satellite state at the true transmit time (satellite clock removed from the code time).
  bool sat_state(const Measurement& m, const GpsTime& rx, SatState& out) {
    if (!eph) { count("ephemeris: no ephemeris"); return false; }
    std::int64_t tx = m.transmit_gps_ns;
    if (!m.code_ok()) {
      if (!have_pos) { count("carrier only: no position yet"); return false; }
      tx = rx.ns - std::llround(kNominalTravelS * 1e9);
    }
    std::string why;
    for (int pass = 0; pass < 2; ++pass) {
      auto st = eph->state(m.sat, tx, &why);
      if (!st) { count("ephemeris: " + why); return false; }
      out = *st;
      if (!m.code_ok()) tx = rx.ns - std::llround((out.pos.p_m - last_pos.p_m).norm() / kSpeedOfLight_mps * 1e9);
      else tx = m.transmit_gps_ns - std::llround(out.clock_bias_s * 1e9);
    }
    auto st = eph->state(m.sat, tx, &why);
    if (!st || !st->pos.p_m.allFinite()) { count("ephemeris: " + (why.empty() ? std::string("numerical failure") : why)); return false; }
    out = *st;
    return true;
  }

  double carrier_hz(const Measurement& m, const SatState& st) const {
    if (std::isfinite(m.carrier_hz)) return m.carrier_hz;
    const int ch = m.sat.sys == Constellation::kGlonass && m.glonass_channel != 99 ? m.glonass_channel : st.glonass_channel;
    return default_carrier_hz(m.sat.sys, ch);
  }

  /// The white (C/N0) part of the code noise model's variance.
  double white_code_variance_m2(const Measurement& m, const SatState& st) const {
    return code_white_variance_m2(opt.spp.code_noise, m.sat.sys, carrier_hz(m, st), m.iono_free, m.cn0_dbhz,
                                  m.cn0_l5_dbhz);
  }

  /// The pseudorange rate's variance from its C/N0 (the Doppler velocity's model without a
  /// reported uncertainty, tdcp.h): RINEX carries no uncertainty, and a log and its RINEX must
  /// smooth alike.
  double rate_variance_m2ps2(const Measurement& m) const { return doppler_cn0_variance_m2ps2(opt.tdcp, m.cn0_dbhz); }

  /// The KF's position covariance (ENU) as reported: with the fixes' common bias, a consider
  /// variance on each horizontal axis (GnssOptions::fix_bias_sigma_h_m; the estimate is the KF's).
  Eigen::Matrix3d reported_cov_enu() const {
    Eigen::Matrix3d c = kf.position_cov_enu();
    if (opt.fix_bias_sigma_h_m > 0.0) {
      c(0, 0) += opt.fix_bias_sigma_h_m * opt.fix_bias_sigma_h_m;
      c(1, 1) += opt.fix_bias_sigma_h_m * opt.fix_bias_sigma_h_m;
    }
    return c;
  }

  /// True when the receiver clock had a hardware discontinuity since the previous epoch.
  bool handle_clock_jump(const MeasurementEpoch& ep) {
    const bool jump =
        prev_hw_disc != kMissingInt && ep.hw_discontinuity != kMissingInt && ep.hw_discontinuity != prev_hw_disc;
    if (jump) {
      count("clock: hardware clock discontinuity (TDCP and KF clock reset)");
      has_prev = false;
      kf.reset_clock(0.0, 1e12);
    }
    prev_hw_disc = ep.hw_discontinuity;
    return jump;
  }

  void process(const std::vector<GnssRawSample>& rows) {
    ++epochs;
    MeasurementEpoch ep;
    if (!build_epoch(rows, opt.measurements, ep, excluded)) { count("epoch: no usable measurement"); return; }
    const bool had_prev = has_prev;
    const bool clock_break = handle_clock_jump(ep);
    std::int64_t d_rx_ns = 0, d_full_bias_ns = 0;  // exact int64 differences; overflow = no link
    const bool rx_linked = had_prev && !__builtin_sub_overflow(ep.rx.ns, prev_rx.ns, &d_rx_ns);
    const bool linked = has_prev && rx_linked && !__builtin_sub_overflow(ep.full_bias_nanos, prev_full_bias_nanos, &d_full_bias_ns);
    const double dt_rx = rx_linked ? static_cast<double>(d_rx_ns) * 1e-9 : 0.0;
    const double dt = linked ? dt_rx : 0.0;
    // Across a hardware clock discontinuity the GPS receive time stays continuous (FullBiasNanos
    // follows the re-set clock), so the code smoother keeps its satellites and propagates them by
    // Doppler, which does not see the receiver clock; the common-step removal takes the code jump.
    const bool smooth_through_break =
        clock_break && opt.smoothing.doppler_through_clock_breaks && dt_rx > 0.0 && dt_rx <= opt.max_epoch_gap_s;
    if (has_prev && (!linked || !(dt > 0.0) || dt > opt.max_epoch_gap_s)) {
      count("epoch: gap or time going backwards (no TDCP)");
      has_prev = false;
    }
    const double d_bias_ns = has_prev ? static_cast<double>(d_full_bias_ns) + (ep.bias_nanos - prev_bias_nanos) : 0.0;
    if (smooth_through_break) smoother.begin_epoch(dt_rx, 0.0, /*carrier_broken=*/true);
    else smoother.begin_epoch(has_prev ? dt : 0.0, d_bias_ns * 1e-9 * kSpeedOfLight_mps);
    std::vector<SppObservation> spp_obs;
    std::vector<CarrierObservation> car_obs;
    std::vector<SmoothingInput> sm_in;
    for (const Measurement& m : ep.meas) {
      SatState st;
      if (!sat_state(m, ep.rx, st)) continue;
      if (m.code_ok()) {
        sm_in.push_back(SmoothingInput{m.sat, m.pseudorange_m, m.adr_ok() ? m.adr_m : kNaN, m.pr_rate_mps, m.iono_free,
                                       m.pseudorange_l1_m, code_band(m.iono_free, m.carrier_hz),
                                       white_code_variance_m2(m, st), rate_variance_m2ps2(m)});
        spp_obs.push_back(SppObservation{m.sat, m.pseudorange_m, m.cn0_dbhz, carrier_hz(m, st), st, m.iono_free, 1.0,
                                         m.iono_free ? m.cn0_l5_dbhz : kNaN});
      }
      CarrierObservation c;
      c.sat = m.sat;
      c.adr_m = m.adr_ok() ? m.adr_m : kNaN;
      c.pr_rate_mps = m.pr_rate_mps;
      c.pr_rate_sigma_mps = m.pr_rate_sigma_mps;
      c.cn0_dbhz = m.cn0_dbhz;
      c.state = st;
      c.carrier_hz = m.carrier_hz;
      c.code_type = m.code_type;
      car_obs.push_back(c);
    }
    {
      std::vector<std::string> why;
      const std::vector<double> sm = smoother.smooth_epoch(sm_in, &why);
      for (std::size_t i = 0; i < sm.size(); ++i) {
        spp_obs[i].pseudorange_m = sm[i];
        if (opt.smoothed_code_white_noise) spp_obs[i].white_var_ratio = smoother.white_variance_ratio(sm_in[i].sat);
        if (!why[i].empty()) count(why[i]);
      }
      if (smoother.last_common_step_m() != 0.0 && std::fabs(smoother.last_common_step_m()) > 1.0)
        count("smoothing: common code-carrier step removed (> 1 m)");
    }
    EpochSolution sol;
    if (opt.record_code_observations) {
      sol.code_obs = spp_obs;
      for (const SmoothingInput& in : sm_in) sol.code_raw_m.push_back(in.pseudorange_m);
    }
    sol.t_ns = ep.t_ns;
    sol.gps_ns = ep.rx.ns;
    sol.sats_tracked = static_cast<int>(rows.size());
    const double tow = geo::gps_ns_to_week_tow(ep.rx.ns).tow_s;
    const SppSolution spp = solve_spp(spp_obs, have_pos ? last_pos : geo::Ecef(), tow,
                                      eph ? eph->klobuchar() : nullptr, opt.spp);
    merge(excluded, spp.excluded);
    if (!spp.ok) count("spp: " + spp.reason);
    sol.spp_ok = spp.ok;
    sol.spp_reason = spp.reason;
    if (spp.ok) {
      sol.spp = spp.pos;
      sol.hdop = spp.hdop;
      sol.pdop = spp.pdop;
      const Eigen::Matrix3d r = geo::ecef_to_enu_rotation(geo::to_geodetic(spp.pos));
      sol.spp_cov_enu = r * spp.pos_cov_ecef * r.transpose();
      sol.spp_variance_factor = spp_variance_factor(spp);
      sol.sats_used = static_cast<int>(spp.used.size());
      sol.used_by_sys = spp.used_by_sys();
      if (!have_pos) { last_pos = spp.pos; have_pos = true; }
    }
    DisplacementSolution disp = displacement(car_obs, dt);
    // carrier phase and Doppler follow the hardware clock; the SPP clock is relative to the
    // receive time already corrected by FullBiasNanos + BiasNanos, so remove that change
    if (disp.ok) {
      disp.clock_change_m -= d_bias_ns * 1e-9 * kSpeedOfLight_mps;
    }
    run_filter(spp, disp, dt, d_bias_ns * 1e-9 * kSpeedOfLight_mps, sol);
    if (disp.ok) {
      sol.tdcp_ok = disp.source == "tdcp";
      sol.disp_source = disp.source;
      sol.disp_dt_s = disp.dt_s;
      sol.tdcp_sats = static_cast<int>(disp.used.size());
      sol.tdcp_disp_m = geo::ecef_to_enu_rotation(geo::to_geodetic(last_pos)) * disp.disp_ecef_m;
    }
    prev_obs = std::move(car_obs);
    prev_rx = ep.rx;
    prev_full_bias_nanos = ep.full_bias_nanos;
    prev_bias_nanos = ep.bias_nanos;
    has_prev = true;
    last_t_ns = ep.t_ns;
    last_gps_ns = ep.rx.ns;
    last_sats_used = sol.sats_used;
    sol.status = status();
    solutions.push_back(sol);
  }

  EstimateStatus status() const {
    if (!kf.initialized()) return EstimateStatus::kNotInitialized;
    if (epochs_since_update >= opt.lost_after_epochs) return EstimateStatus::kLost;
    if (epochs_since_update > 0 || last_sats_used < opt.min_sats_ok) return EstimateStatus::kDegraded;
    return EstimateStatus::kOk;
  }

  DisplacementSolution displacement(const std::vector<CarrierObservation>& obs, double dt) {
    DisplacementSolution none;
    if (!have_pos) return none;
    if (!has_prev) {
      // no link to the previous epoch (gap, clock discontinuity): the Doppler velocity of this
      // epoch alone is still a measurement for the kinematic KF (over a nominal 1 s)
      if (!opt.use_doppler_fallback || !kf.initialized()) return none;
      DisplacementSolution v = solve_doppler(obs, 1.0, last_pos, opt.tdcp);
      merge(excluded, v.excluded);
      if (!v.ok) count("doppler: " + v.reason);
      return v;
    }
    DisplacementSolution d = solve_tdcp(prev_obs, obs, dt, last_pos, opt.tdcp);
    merge(excluded, d.excluded);
    if (d.ok && !d.self_checked && kf.initialized()) {
      // TDCP is the KF's time update, not gated by it: a solution its own test could not
      // check is checked against the filter's prediction instead
      const double m2 = kf.displacement_mahalanobis2(d.disp_ecef_m, d.cov_ecef_m2, d.dt_s > 0.0 ? d.dt_s : dt);
      if (!(m2 <= chi_square_quantile(opt.tdcp.fde_false_alarm, 3))) {
        d.ok = false;
        d.reason = "unchecked by its own test and inconsistent with the KF";
        if (opt.use_doppler_fallback) count("tdcp: " + d.reason + " (Doppler used)");  // else counted below
      }
    }
    if (d.ok || !opt.use_doppler_fallback) {
      if (!d.ok) count("tdcp: " + d.reason);
      return d;
    }
    DisplacementSolution v = solve_doppler(obs, dt, last_pos, opt.tdcp);
    merge(excluded, v.excluded);
    if (!v.ok) count("doppler: " + v.reason);
    return v;
  }

  /// d_bias_m: c * change of FullBiasNanos + BiasNanos since the previous epoch. The KF clock is
  /// the SPP clock (receive time corrected by that bias); its drift is the hardware clock's
  /// (what Doppler and carrier see), so a prediction moves the clock by drift * dt - d_bias_m.
  void run_filter(const SppSolution& spp, const DisplacementSolution& disp, double dt, double d_bias_m,
                  EpochSolution& sol) {
    if (kf.initialized()) {
      if (disp.ok && disp.source == "tdcp") {
        // the displacement's own covariance plus a process noise growing as dt^3 (white
        // acceleration, Bar-Shalom 2001 Sec. 6.2): q per 1 s epoch, 125 q over a 5 s gap
        const double span = std::max(1.0, disp.dt_s > 0.0 ? disp.dt_s : dt);
        const Eigen::Matrix3d q = Eigen::Matrix3d::Identity() * opt.kalman.displacement_q_m2 * (span * span * span - 1.0);
        kf.predict(disp.disp_ecef_m, disp.cov_ecef_m2 + q, disp.clock_change_m, disp.clock_change_var_m2, span);
        // the mean velocity over the interval keeps the velocity state for later coasting
        kf.set_velocity(disp.disp_ecef_m / span, disp.cov_ecef_m2 / (span * span),
                        (disp.clock_change_m + d_bias_m) / span, disp.clock_change_var_m2 / (span * span));
      } else {
        // constant-velocity prediction (the dynamics' acceleration PSD), then the Doppler
        // velocity of this epoch: with the velocity measured at both ends of a gap the
        // position follows the mean velocity instead of this epoch's velocity x dt
        // without a link the time since the last epoch still sets the prediction span
        const double since_last_s = last_gps_ns != 0 ? static_cast<double>(sol.gps_ns - last_gps_ns) * 1e-9 : 0.0;
        kf.coast(dt > 0.0 ? dt : (since_last_s > 0.0 ? since_last_s : 1.0));
        kf.shift_clock(-d_bias_m);
        if (disp.ok && disp.dt_s > 0.0) {
          const double t = disp.dt_s;
          const KalmanUpdateResult v = kf.update_velocity(disp.disp_ecef_m / t, disp.cov_ecef_m2 / (t * t),
                                                          (disp.clock_change_m + d_bias_m) / t,
                                                          disp.clock_change_var_m2 / (t * t));
          if (!v.accepted) count("kf: velocity rejected (robust test)");
        }
      }
    }
    ++epochs_since_update;
    if (spp.ok) {
      // the SPP clock is the clock of its reference system (GPS when present); when that
      // system changes, the clock state jumps by an ISB: re-initialise the clock instead of
      // rejecting updates until the filter hard-resets
      if (kf.initialized() && have_clock_system && (spp.clock_system != kf_clock_system || spp.clock_band != kf_clock_band)) {
        count("kf: reference clock system changed (clock re-initialised)");
        kf.reset_clock(spp.clock_m, 1e12);
      }
      kf_clock_system = spp.clock_system;
      kf_clock_band = spp.clock_band;
      have_clock_system = true;
      sol.clock_system = spp.clock_system;
      const bool was_initialized = kf.initialized();
      // R = the SPP covariance scaled by its a-posteriori variance factor chi2/dof (at least 1):
      // the a-priori C/N0 model does not know the multipath of a moving phone, the residuals do
      const double vf_fit = spp_variance_factor(spp);
      const double vf = opt.scale_fix_by_variance_factor && std::isfinite(vf_fit) ? std::max(1.0, vf_fit) : 1.0;
      const double since_fix_s = last_fix_gps_ns != 0 ? static_cast<double>(sol.gps_ns - last_fix_gps_ns) * 1e-9 : 1.0;
      last_fix_gps_ns = sol.gps_ns;
      const KalmanUpdateResult u =
          kf.update(spp.pos, spp.pos_cov_ecef * vf, spp.clock_m, spp.clock_var_m2 * vf, since_fix_s);
      sol.kf_update_accepted = u.accepted;
      if (u.accepted) epochs_since_update = 0;
      else count("kf: SPP fix rejected (robust test)");
      if (u.accepted && u.robust_weight < 1.0) count("kf: SPP fix down-weighted (IGG-III)");
      if (u.reset && was_initialized) count("kf: reset to the SPP fix");
    }
    if (!kf.initialized()) return;
    sol.kf_ok = true;
    sol.kf = kf.position();
    sol.clock_m = kf.clock_m();
    sol.kf_cov_enu = reported_cov_enu();
    sol.kf_vel_enu_mps = geo::ecef_to_enu_rotation(geo::to_geodetic(kf.position())) * kf.velocity_ecef_mps();
    last_pos = kf.position();
    if (!have_frame) { frame = geo::LocalFrame(geo::to_geodetic(last_pos)); have_frame = true; }
  }
};

GnssEngine::GnssEngine(const GnssOptions& options, std::shared_ptr<const EphemerisStore> eph, std::uint64_t seed)
    : impl_(std::make_unique<Impl>()) {
  impl_->opt = options;
  impl_->eph = std::move(eph);
  impl_->seed = seed;
  impl_->kf = RobustKalman(options.kalman);
  impl_->smoother = CodeSmoother(options.smoothing);
}

GnssEngine::~GnssEngine() = default;
GnssEngine::GnssEngine(GnssEngine&&) noexcept = default;
GnssEngine& GnssEngine::operator=(GnssEngine&&) noexcept = default;

void GnssEngine::feed(const GnssRawSample& s) {
  Impl& m = *impl_;
  if (s.time_nanos == kMissingInt) { m.count("row: TimeNanos missing"); return; }
  if (!m.pending.empty() && m.pending.front().time_nanos != s.time_nanos) flush();
  m.pending.push_back(s);
}

void GnssEngine::feed_epoch(const std::vector<GnssRawSample>& rows) {
  flush();
  Impl& m = *impl_;
  std::vector<GnssRawSample> ok;
  ok.reserve(rows.size());
  for (const GnssRawSample& r : rows) {
    if (r.time_nanos == kMissingInt) { m.count("row: TimeNanos missing"); continue; }
    if (!ok.empty() && r.time_nanos != ok.front().time_nanos) {  // not one epoch after all
      m.process(ok);
      ok.clear();
    }
    ok.push_back(r);
  }
  if (!ok.empty()) m.process(ok);
}

void GnssEngine::feed(const NavMessageSample& s) {
  Impl& m = *impl_;
  if (s.type != kGpsL1CaNavType) { m.count("nav: unsupported message type"); return; }
  if (m.last_gps_ns == 0) { m.count("nav: no GPS time yet for the week number"); return; }
  if (!m.owned) {
    m.owned = m.eph ? std::make_shared<EphemerisStore>(*m.eph) : std::make_shared<EphemerisStore>();
    m.eph = m.owned;
  }
  std::string why;
  m.owned->add_gps_lnav_subframe(s.svid, s.sub_message_id, s.data, geo::gps_ns_to_week_tow(m.last_gps_ns).week, &why);
  if (!why.empty()) m.count("nav: " + why);
}

void GnssEngine::flush() {
  Impl& m = *impl_;
  if (m.pending.empty()) return;
  std::vector<GnssRawSample> rows;
  rows.swap(m.pending);
  m.process(rows);
}

void GnssEngine::reset() {
  Impl& m = *impl_;
  m.kf = RobustKalman(m.opt.kalman);
  m.smoother.reset();
  m.has_prev = false;
  m.have_pos = false;
  m.epochs_since_update = 0;
  m.have_clock_system = false;
  m.last_fix_gps_ns = 0;
}

Estimate GnssEngine::estimate() const {
  const Impl& m = *impl_;
  Estimate e;
  e.engine = EngineKind::kGnss;
  e.t_ns = m.last_t_ns;
  if (!m.kf.initialized()) {
    e.reason = "GNSS: no fix yet";
    return e;
  }
  e.position = geo::to_geodetic(m.kf.position());
  e.en_m = m.frame.to_enu(m.kf.position()).p_m.head<2>();
  const Eigen::Matrix3d cov = m.reported_cov_enu();
  e.cov_en_m2 = cov.topLeftCorner<2, 2>();
  e.vertical_sigma_m = std::sqrt(std::max(cov(2, 2), 0.0));
  if (m.epochs_since_update >= m.opt.lost_after_epochs) {
    e.status = EstimateStatus::kLost;
    e.reason = "GNSS: no accepted fix for " + std::to_string(m.epochs_since_update) + " epochs";
  } else if (m.epochs_since_update > 0) {
    e.status = EstimateStatus::kDegraded;
    e.reason = "GNSS: coasting on carrier phase / Doppler";
  } else if (m.last_sats_used < m.opt.min_sats_ok) {
    e.status = EstimateStatus::kDegraded;
    e.reason = "GNSS: few satellites (" + std::to_string(m.last_sats_used) + ")";
  } else {
    e.status = EstimateStatus::kOk;
    e.reason = "GNSS: SPP + TDCP Kalman filter";
  }
  return e;
}

std::vector<EpochSolution> GnssEngine::take_solutions() {
  std::vector<EpochSolution> out;
  out.swap(impl_->solutions);
  return out;
}

const std::map<std::string, std::int64_t>& GnssEngine::exclusions() const { return impl_->excluded; }
std::int64_t GnssEngine::epochs() const { return impl_->epochs; }
std::uint64_t GnssEngine::seed() const { return impl_->seed; }

}  // namespace pdnav::gnss
