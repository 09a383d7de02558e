#include "support/replay_support.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <stdexcept>

#include <unistd.h>

#include <Eigen/LU>

namespace pdnav::cli {
namespace {
/// Free text in one CSV field: its commas become semicolons (the files are not quoted).
std::string csv_text(std::string s) {
  std::replace(s.begin(), s.end(), ',', ';');
  return s;
}
}  // namespace

std::vector<double> parse_number_list(const std::string& text, const std::string& what) {
  std::vector<double> out;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const std::size_t comma = text.find(',', pos);
    const std::string tok = text.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
    try {
      std::size_t used = 0;
      const double v = std::stod(tok, &used);
      if (used != tok.size() || !std::isfinite(v)) throw std::invalid_argument(tok);
      out.push_back(v);
    } catch (const std::exception&) {
      throw std::invalid_argument(what + ": '" + tok + "' is not a number in '" + text + "'");
    }
    if (comma == std::string::npos) break;
    pos = comma + 1;
  }
  return out;
}

ProgressBar::ProgressBar(std::ostream* out, std::string label)
    : out_(out), label_(std::move(label)), tty_(out != nullptr && isatty(STDERR_FILENO) != 0) {}

void ProgressBar::update(double fraction) {
  if (!out_) return;
  int pct = static_cast<int>(std::clamp(fraction, 0.0, 1.0) * 100.0);
  if (!tty_) pct -= pct % 10;
  if (pct == last_percent_) return;
  last_percent_ = pct;
  if (tty_)
    *out_ << "\r" << label_ << ": " << std::setw(3) << pct << " %" << std::flush;
  else
    *out_ << label_ << ": " << pct << " %\n";
}

void ProgressBar::done() {
  if (!out_ || last_percent_ < 0) return;
  if (tty_) *out_ << "\r" << label_ << ": 100 %\n";
  else if (last_percent_ != 100) *out_ << label_ << ": 100 %\n";
}

nlohmann::json ErrorStats::to_json() const {
  return {{"epochs_with_reference", n}, {"drms_m", drms_m}, {"rms_e_m", rms_e_m}, {"rms_n_m", rms_n_m},
          {"p50_horizontal_m", p50_h_m}, {"p95_horizontal_m", p95_h_m}, {"coverage_1sigma", coverage_1sigma}, {"coverage_68", coverage_68},
          {"median_percentile", std::isfinite(median_percentile) ? nlohmann::json(median_percentile) : nlohmann::json(nullptr)}};
}

double fix_sigma_m(const FixSample& f, double default_accuracy_m) {
  return (std::isfinite(f.accuracy_m) && f.accuracy_m > 0.0 ? f.accuracy_m : default_accuracy_m) *
         (1.0 / FixSample::kAccuracyRadiusPerSigma);
}

bool is_gps_reference_fix(const FixSample& f) {
  std::string p = f.provider;
  std::transform(p.begin(), p.end(), p.begin(), [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return p == "GPS" && std::isfinite(f.lat_deg) && std::isfinite(f.lon_deg);
}

void ReplayRecorder::observe_reference(const Sample& s) {
  if (const auto* t = std::get_if<TruthSample>(&s)) {
    if (std::isfinite(t->lat_deg) && std::isfinite(t->lon_deg))
      truth_.push_back({t->t_ns, geo::Geodetic::from_deg(t->lat_deg, t->lon_deg, std::isfinite(t->h_m) ? t->h_m : 0.0)});
  } else if (const auto* f = std::get_if<FixSample>(&s)) {
    if (is_gps_reference_fix(*f))
      fixes_.push_back({f->t_ns, geo::Geodetic::from_deg(f->lat_deg, f->lon_deg, std::isfinite(f->alt_m) ? f->alt_m : 0.0)});
  }
}

void ReplayRecorder::observe_estimate(const Estimate& e) {
  if (!e.valid()) return;
  if (e.t_ns == last_t_ && e.status == last_status_) return;  // unchanged since the last sample
  last_t_ = e.t_ns;
  last_status_ = e.status;
  Epoch ep;
  ep.est = e;
  epochs_.push_back(ep);
}

bool ReplayRecorder::reference_at(TimeNs t, geo::Geodetic* out) const {
  if (truth_.size() >= 2) {
    auto it = std::lower_bound(truth_.begin(), truth_.end(), t, [](const Ref& r, TimeNs x) { return r.t_ns < x; });
    if (it == truth_.end() || it == truth_.begin()) {
      const Ref& r = it == truth_.end() ? truth_.back() : truth_.front();
      if (std::llabs(r.t_ns - t) > kNsPerS) return false;
      *out = r.p;
      return true;
    }
    const Ref& b = *it;
    const Ref& a = *(it - 1);
    const double w = b.t_ns == a.t_ns ? 0.0 : static_cast<double>(t - a.t_ns) / static_cast<double>(b.t_ns - a.t_ns);
    *out = geo::Geodetic{a.p.lat_rad + w * (b.p.lat_rad - a.p.lat_rad), a.p.lon_rad + w * (b.p.lon_rad - a.p.lon_rad),
                         a.p.h_m + w * (b.p.h_m - a.p.h_m)};
    return true;
  }
  if (!fixes_.empty()) {
    auto it = std::lower_bound(fixes_.begin(), fixes_.end(), t, [](const Ref& r, TimeNs x) { return r.t_ns < x; });
    const Ref* best = nullptr;
    if (it != fixes_.end()) best = &*it;
    if (it != fixes_.begin() && (!best || std::llabs((it - 1)->t_ns - t) < std::llabs(best->t_ns - t))) best = &*(it - 1);
    if (best && std::llabs(best->t_ns - t) <= kNsPerS) {
      *out = best->p;
      return true;
    }
  }
  return false;
}

void ReplayRecorder::finish() {
  // step rows come at their steps' own times; a step released late (bout gate) may be earlier
  // than the row before it
  std::stable_sort(epochs_.begin(), epochs_.end(), [](const Epoch& a, const Epoch& b) { return a.est.t_ns < b.est.t_ns; });
  std::sort(truth_.begin(), truth_.end(), [](const Ref& a, const Ref& b) { return a.t_ns < b.t_ns; });
  std::sort(fixes_.begin(), fixes_.end(), [](const Ref& a, const Ref& b) { return a.t_ns < b.t_ns; });
  for (Epoch& ep : epochs_) {
    geo::Geodetic ref;
    if (!reference_at(ep.est.t_ns, &ref)) continue;
    ep.has_ref = true;
    ep.ref = ref;
    const geo::Enu d = geo::LocalFrame(ref).to_enu(ep.est.position);
    ep.err_e_m = d.e_m();
    ep.err_n_m = d.n_m();
    // inside the 1-sigma ellipse: Mahalanobis distance^2 <= 1 (39.3 % nominal in 2D)
    ep.mahalanobis2 = mahalanobis2(ep.est.cov_en_m2, Eigen::Vector2d(ep.err_e_m, ep.err_n_m));
    ep.inside_1sigma = ep.mahalanobis2 <= 1.0;
  }
}

std::map<std::string, std::int64_t> ReplayRecorder::epochs_by_engine() const {
  std::map<std::string, std::int64_t> m;
  for (const Epoch& e : epochs_) ++m[to_string(e.est.engine)];
  return m;
}

std::string ReplayRecorder::reference_kind() const {
  if (truth_.size() >= 2) return "truth";
  if (!fixes_.empty()) return "gps-fix";
  return "none";
}

ErrorStats ReplayRecorder::error_stats() const {
  ErrorStats s;
  std::vector<double> h, m2;
  double se = 0, sn = 0;
  std::int64_t inside = 0, inside68 = 0;
  for (const Epoch& e : epochs_) {
    if (!e.has_ref) continue;
    ++s.n;
    m2.push_back(e.mahalanobis2);
    se += e.err_e_m * e.err_e_m;
    sn += e.err_n_m * e.err_n_m;
    h.push_back(std::hypot(e.err_e_m, e.err_n_m));
    inside += e.inside_1sigma ? 1 : 0;
    inside68 += e.mahalanobis2 <= kOneSigmaM2 ? 1 : 0;
  }
  if (s.n == 0) return s;
  const double n = static_cast<double>(s.n);
  s.rms_e_m = std::sqrt(se / n);
  s.rms_n_m = std::sqrt(sn / n);
  s.drms_m = std::sqrt((se + sn) / n);
  std::sort(h.begin(), h.end());
  auto pct = [&](double p) { return h[std::min(h.size() - 1, static_cast<std::size_t>(p * static_cast<double>(h.size() - 1) + 0.5))]; };
  s.p50_h_m = pct(0.50);
  s.p95_h_m = pct(0.95);
  s.coverage_1sigma = static_cast<double>(inside) / n;
  s.coverage_68 = static_cast<double>(inside68) / n;
  s.median_percentile = chi2_2dof_percent(median_mahalanobis2(std::move(m2)));
  return s;
}

void ReplayRecorder::write_track_csv(const std::string& path) const {
  std::ofstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot create");
  f << "t_ns,engine,status,lat_deg,lon_deg,h_m,e_m,n_m,cov_ee_m2,cov_en_m2,cov_nn_m2,semi_major_m,semi_minor_m,"
       "orientation_deg,ref_lat_deg,ref_lon_deg,err_e_m,err_n_m,reason,mode_change\n";
  f << std::setprecision(12);
  std::size_t next_change = 0;
  for (const Epoch& ep : epochs_) {
    const Estimate& e = ep.est;
    const ErrorEllipse el = e.ellipse();
    f << e.t_ns << ',' << to_string(e.engine) << ',' << to_string(e.status) << ',' << e.position.lat_deg() << ','
      << e.position.lon_deg() << ',' << e.position.h_m << ',' << e.en_m.x() << ',' << e.en_m.y() << ','
      << e.cov_en_m2(0, 0) << ',' << e.cov_en_m2(0, 1) << ',' << e.cov_en_m2(1, 1) << ',' << el.semi_major_m << ','
      << el.semi_minor_m << ',' << rad_to_deg(el.orientation_rad) << ',';
    if (ep.has_ref)
      f << ep.ref.lat_deg() << ',' << ep.ref.lon_deg() << ',' << ep.err_e_m << ',' << ep.err_n_m;
    else
      f << ",,,";
    f << ',' << csv_text(e.reason) << ',' << mode_changes_up_to(e.t_ns, &next_change) << '\n';
  }
}

void ReplayRecorder::observe_engines(TimeNs t_ns, const std::vector<Estimate>& engines) {
  if (!engines_due(t_ns)) return;
  last_engines_t_ = t_ns;
  for (Estimate e : engines) {
    if (!e.valid()) continue;
    e.t_ns = t_ns;  // the epoch it was read at (an engine's own time may lag it)
    engine_rows_.push_back(std::move(e));
  }
}

void ReplayRecorder::write_engines_csv(const std::string& path) const {
  std::ofstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot create");
  f << "t_ns,engine,status,lat_deg,lon_deg,cov_ee_m2,cov_en_m2,cov_nn_m2,semi_major_m,ref_lat_deg,ref_lon_deg,err_e_m,"
       "err_n_m,reason\n";
  f << std::setprecision(12);
  for (const Estimate& e : engine_rows_) {
    f << e.t_ns << ',' << to_string(e.engine) << ',' << to_string(e.status) << ',' << e.position.lat_deg() << ','
      << e.position.lon_deg() << ',' << e.cov_en_m2(0, 0) << ',' << e.cov_en_m2(0, 1) << ',' << e.cov_en_m2(1, 1) << ','
      << e.ellipse().semi_major_m << ',';
    geo::Geodetic ref;
    if (reference_at(e.t_ns, &ref)) {
      const geo::Enu d = geo::LocalFrame(ref).to_enu(e.position);
      f << ref.lat_deg() << ',' << ref.lon_deg() << ',' << d.e_m() << ',' << d.n_m();
    } else {
      f << ",,,";
    }
    f << ',' << csv_text(e.reason) << '\n';
  }
}

void ReplayRecorder::set_mode_changes(std::vector<std::pair<TimeNs, std::string>> changes) {
  std::stable_sort(changes.begin(), changes.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  mode_changes_ = std::move(changes);
}

std::string ReplayRecorder::mode_changes_up_to(TimeNs t_ns, std::size_t* next) const {
  std::string out;
  for (; *next < mode_changes_.size() && mode_changes_[*next].first <= t_ns; ++*next) {
    if (!out.empty()) out += " | ";
    out += mode_changes_[*next].second;
  }
  return csv_text(std::move(out));
}

std::vector<std::pair<double, double>> ellipse_polygon(const Estimate& e, double k, int points) {
  const ErrorEllipse el = e.ellipse();
  const geo::LocalFrame frame(e.position);
  std::vector<std::pair<double, double>> ring;
  for (int i = 0; i <= points; ++i) {
    const double a = 2.0 * kPi * i / points;
    const double u = k * el.semi_major_m * std::cos(a), v = k * el.semi_minor_m * std::sin(a);
    // major axis at orientation (clockwise from north): unit (sin, cos); minor perpendicular
    const double so = std::sin(el.orientation_rad), co = std::cos(el.orientation_rad);
    const double east = u * so + v * co, north = u * co - v * so;
    const geo::Geodetic g = frame.to_geodetic(geo::Enu(east, north, 0.0));
    ring.emplace_back(g.lon_deg(), g.lat_deg());
  }
  return ring;
}

void ReplayRecorder::write_geojson(const std::string& path, std::size_t max_ellipses) const {
  nlohmann::json features = nlohmann::json::array();
  nlohmann::json line = nlohmann::json::array();
  for (const Epoch& ep : epochs_) line.push_back({ep.est.position.lon_deg(), ep.est.position.lat_deg()});
  features.push_back({{"type", "Feature"},
                      {"properties", {{"kind", "track"}}},
                      {"geometry", {{"type", "LineString"}, {"coordinates", line}}}});
  const std::size_t stride = std::max<std::size_t>(1, epochs_.size() / std::max<std::size_t>(1, max_ellipses));
  for (std::size_t i = 0; i < epochs_.size(); i += stride) {
    const Estimate& e = epochs_[i].est;
    const ErrorEllipse el = e.ellipse();
    if (!std::isfinite(el.semi_major_m)) continue;
    nlohmann::json ring = nlohmann::json::array();
    for (const auto& [lon, lat] : ellipse_polygon(e, 1.0)) ring.push_back({lon, lat});
    features.push_back({{"type", "Feature"},
                        {"properties", {{"kind", "ellipse-1sigma"}, {"t_ns", e.t_ns}, {"engine", to_string(e.engine)},
                                        {"status", to_string(e.status)}, {"semi_major_m", el.semi_major_m},
                                        {"semi_minor_m", el.semi_minor_m}}},
                        {"geometry", {{"type", "Polygon"}, {"coordinates", nlohmann::json::array({ring})}}}});
  }
  std::ofstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot create");
  f << nlohmann::json({{"type", "FeatureCollection"}, {"features", features}}).dump() << "\n";
}

}  // namespace pdnav::cli

namespace pdnav::cli {

nlohmann::json pdr_calibration_json(const fusion::PdrCalibration& c) {
  return {{"valid", c.valid},
          {"scale", c.scale},
          {"scale_sigma", c.scale_sigma},
          {"heading_bias_deg", rad_to_deg(c.heading_bias_rad)},
          {"heading_bias_sigma_deg", rad_to_deg(c.heading_bias_sigma_rad)},
          {"window_epochs", c.epochs},
          {"baseline_m", c.baseline_m},
          {"residual_tau_epochs", c.residual_tau},
          {"course_epochs", c.course_epochs},
          {"course_bias_deg", rad_to_deg(c.course_bias_rad)},
          {"course_bias_sigma_deg", rad_to_deg(c.course_bias_sigma_rad)},
          {"speed_epochs", c.speed_epochs},
          {"speed_scale", c.speed_scale},
          {"speed_scale_sigma", c.speed_scale_sigma},
          {"positions_used", c.positions_used}};
}

std::string accel_rate_warning(double rate_hz) {
  char b[320];
  char every[64] = "";
  if (rate_hz > 0.0 && rate_hz < 1.0) std::snprintf(every, sizeof every, " (a sample every %.0f s)", 1.0 / rate_hz);
  std::snprintf(b, sizeof b,
                "accelerometer at %.3g Hz%s: the step detector is measured at 50-200 Hz and misses steps below %.0f Hz "
                "(TYREX at 25 Hz: median step error 10 %%, length ratio 0.83; at 10 Hz 0.28); record at 50 Hz or more",
                rate_hz, every, pdr::Pdr::kMinAccelRateHz);
  return b;
}

nlohmann::json pdr_summary_json(const pdr::Pdr& pdr, std::int64_t navigator_steps, TimeNs t0_ns) {
  nlohmann::json j;
  j["steps"] = navigator_steps;
  j["distance_m"] = pdr.distance_m();
  j["mount"] = pdr::to_string(pdr.options().heading.mount);
  // issue 27: which sensors the PDR had and the absolute heading they can give
  j["sensor_set"] = pdr.sensor_set().name();
  j["heading_reference"] = pdr.sensor_set().heading_reference();
  const double rate_hz = pdr.accel_rate_hz();
  j["accel_rate_hz"] = std::isfinite(rate_hz) ? nlohmann::json(rate_hz) : nlohmann::json();
  j["accel_rate_warning"] = std::isfinite(rate_hz) && rate_hz < pdr::Pdr::kMinAccelRateHz
                                ? accel_rate_warning(rate_hz)
                                : std::string();
  const pdr::PdrCounters c = pdr.counters();
  j["steps_refused_handling"] = c.steps_discarded_by_motion;
  j["steps_dropped_by_bout_gate"] = c.steps_discarded_by_bout_gate;
  j["steps_added_at_stride_midpoints"] = c.steps_added_at_stride_midpoints;
  j["steps_from_handling_hangover"] = c.steps_from_handling_hangover;
  j["forward_channel_candidates"] = c.forward_channel_candidates;
  j["steps_before_their_bouts_direction"] = c.steps_before_their_bouts_direction;
  j["steps_with_undecided_direction"] = c.steps_with_undecided_direction;
  j["steps_refused_vehicle"] = c.steps_discarded_by_vehicle;
  j["max_step_delay_s"] = c.max_step_delay_s;  // longest step-to-emission latency
  j["max_step_delay_at_s"] = c.max_step_delay_s > 0.0 ? ns_to_s(c.max_step_delay_at_ns - t0_ns) : 0.0;
  nlohmann::json rides = nlohmann::json::array();
  for (const pdr::MotionSpan& v : pdr.vehicle_spans())
    rides.push_back({{"start_s", ns_to_s(v.t_start_ns - t0_ns)}, {"end_s", ns_to_s(v.t_end_ns - t0_ns)}});
  j["vehicle_spans"] = rides;
  nlohmann::json handled = nlohmann::json::array();
  for (const pdr::MotionSpan& v : pdr.handling_spans())
    handled.push_back({{"start_s", ns_to_s(v.t_start_ns - t0_ns)}, {"end_s", ns_to_s(v.t_end_ns - t0_ns)}});
  j["handling_spans"] = handled;
  j["vehicle_max_score_s"] = c.vehicle_max_score_s;
  j["vehicle_kinematic_max_mps2"] = c.vehicle_kinematic_max_mps2;
  j["magnetometer_readings_trusted"] = c.mag_readings_trusted;
  j["magnetometer_readings_disturbed"] = c.mag_readings_disturbed;
  const pdr::MagCalibration& cal = pdr.mag_calibration();
  j["mag_calibration"] = {{"active", cal.active()},
                          {"bias_ut", {cal.bias_ut().x(), cal.bias_ut().y(), cal.bias_ut().z()}},
                          {"radius_ut", std::isfinite(cal.radius_ut()) ? nlohmann::json(cal.radius_ut()) : nlohmann::json()},
                          {"residual", std::isfinite(cal.residual()) ? nlohmann::json(cal.residual()) : nlohmann::json()},
                          {"method", cal.gyro_aided() ? "gyro-aided pairs" : "sphere"},
                          {"active_from_s", cal.active_from_ns() >= 0 ? nlohmann::json(ns_to_s(cal.active_from_ns() - t0_ns)) : nlohmann::json()},
                          {"gyro_bias_dps", {rad_to_deg(cal.gyro_bias_radps().x()), rad_to_deg(cal.gyro_bias_radps().y()), rad_to_deg(cal.gyro_bias_radps().z())}},
                          {"pairs_gated", cal.pairs_gated()},
                          {"pair_restarts", cal.pair_restarts()},
                          {"pair_residual_ut", std::isfinite(cal.pair_residual_ut()) ? nlohmann::json(cal.pair_residual_ut()) : nlohmann::json()},
                          {"explained", std::isfinite(cal.last_explained()) ? nlohmann::json(cal.last_explained()) : nlohmann::json()},
                          {"bias_sigma_ut", std::isfinite(cal.bias_sigma_ut()) ? nlohmann::json(cal.bias_sigma_ut()) : nlohmann::json()},
                          {"fits_accepted", cal.fits_accepted()},
                          {"fits_refused", cal.refusals()}};
  if (pdr.gyro_bias_at_rest_used()) {  // an uncalibrated gyro without its drift (gyro_bias.h)
    const Eigen::Vector3d b = pdr.gyro_bias_at_rest().bias_radps();
    j["gyro_bias_at_rest"] = {{"still_blocks", pdr.gyro_bias_at_rest().still_blocks()},
                              {"bias_dps", {rad_to_deg(b.x()), rad_to_deg(b.y()), rad_to_deg(b.z())}}};
  }
  nlohmann::json bouts = nlohmann::json::array();
  for (const pdr::PlacementBout& b : pdr.placements()) {
    bouts.push_back({{"placement", pdr::to_string(b.placement)},
                     {"start_s", ns_to_s(b.t_start_ns - t0_ns)},
                     {"end_s", ns_to_s(b.t_end_ns - t0_ns)},
                     {"forward_phone", {b.forward_phone.x(), b.forward_phone.y(), b.forward_phone.z()}},
                     {"phase_corr", b.phase_corr},
                     {"tilt_swing_deg", std::isfinite(b.tilt_swing_deg) ? nlohmann::json(b.tilt_swing_deg) : nlohmann::json()}});
  }
  j["placements"] = bouts;
  // which absolute reference held the heading, per segment of consecutive steps (issue 27)
  nlohmann::json sources = nlohmann::json::array();
  std::map<std::string, std::int64_t> steps_by_source;
  for (const pdr::HeadingSourceSpan& span : pdr.heading_sources()) {
    sources.push_back({{"source", pdr::to_string(span.source)},
                       {"start_s", ns_to_s(span.t_start_ns - t0_ns)},
                       {"end_s", ns_to_s(span.t_end_ns - t0_ns)},
                       {"steps", span.steps}});
    steps_by_source[pdr::to_string(span.source)] += span.steps;
  }
  j["heading_sources"] = sources;
  j["steps_by_heading_source"] = steps_by_source;
  return j;
}

}  // namespace pdnav::cli
