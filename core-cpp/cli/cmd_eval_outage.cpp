// pdnav eval-outage LOG...: a GNSS outage cut into a real (or simulated) recording (issue 28).
// For each recording with phone fixes (Fix rows, from GnssLogger or a logger's location table),
// GnssLogger Raw epochs, or Truth rows: all GNSS (Raw and Fix) is removed over an outage window
// and the recording is replayed through the Navigator (fused, --engine auto), and through dead
// reckoning restarted at the last fix before the window with uncalibrated PDR (--engine dr);
// both are scored inside the window against the withheld fixes (or Truth where present).
// Definitions (window, coverage, jump): docs/fusion.md "eval-outage".
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <Eigen/LU>
#include <nlohmann/json.hpp>

#include "pdnav/fusion/navigator.h"
#include "pdnav/geo/frames.h"
#include "pdnav/gnss/ephemeris.h"
#include "pdnav/io/sample_source.h"
#include "pdnav/pdr/pdr.h"
#include "pdnav/route/walk_graph.h"
#include "pdnav/terrain/dem.h"
#include "support/eval_support.h"
#include "support/replay_support.h"
#include "support/sources.h"

namespace pdnav::cli {
namespace {

constexpr double kNaNd = std::numeric_limits<double>::quiet_NaN();
constexpr double kJumpAfterS = 60.0;       // re-acquisition jumps are looked for this long after the window

struct EvalOutageArgs {
  std::vector<std::string> logs;
  std::string format = "auto";
  double start_frac = 0.4, length_frac = 0.4, max_s = 300.0;
  double start_s = kNaNd, length_s = kNaNd;  // absolute (from the start of the GNSS span), override the fractions
  std::vector<double> start_fracs;  // several windows per recording (a sweep), replaces start_frac
  std::string dem, graph;
  std::vector<std::string> nav;
  std::string out_dir;
  std::string mount = "auto";
  double height_m = kNaNd;
  std::uint64_t seed = 1;
  bool quiet = false;
  std::string fusion_model = "issue28";
};

/// A reference position: a withheld phone fix (with its stated 1-sigma per axis) or Truth (0).
struct RefPoint {
  TimeNs t_ns = 0;
  geo::Geodetic p;
  double sigma_m = 0.0;
};

/// The Navigator's shown estimate at each reference epoch.
struct Track {
  std::vector<bool> valid;
  std::vector<Eigen::Vector2d> en_m;
  std::vector<Eigen::Matrix2d> cov;
  std::vector<std::string> mode;
};

struct WalkResult {
  std::string name;
  std::string reference;  // "truth" or "fixes"
  double span_s = 0, w0_s = 0, w1_s = 0;  // GNSS span, window (s from the span start)
  bool gnss_in_log = true;  // false: no GNSS at all, the span is the reference's
  int epochs_in_window = 0;
  double fused_rms_m = kNaNd, dr_rms_m = kNaNd, fused_end_m = kNaNd, dr_end_m = kNaNd, ratio = kNaNd;
  int covered = 0;
  // The window's median squared Mahalanobis distance, and where it falls in the chi^2(2) the
  // stated covariance claims (percent; 50 = the median error is the stated median): one window
  // is one draw of an error correlated over minutes, so its coverage is near 0 or 1; this says
  // how far inside or outside the 68 % region the window sat
  double median_m2 = kNaNd, median_percentile = kNaNd;
  double max_jump_sigma = 0.0;
  double max_jump_t_s = kNaNd;
  fusion::PdrCalibration cal;      // published before the window
  fusion::PdrCalibration cal_fit;  // the latest window fit before it (published or not)
  std::int64_t removed_raw = 0, removed_fix = 0;
  double dr_start_sigma_m = kNaNd;
};

/// "; course over ground B +- S deg (N epochs)" when the GNSS course (a Fix's bearing or a
/// TDCP/Doppler displacement's direction) went into the heading, "; speed scale ..." when the
/// GNSS speed went into the scale, "; positions not used (baseline)" when the fit lacked one.
std::string calibration_note(const fusion::PdrCalibration& c) {
  std::string out;
  char b[128];
  if (c.course_epochs > 0 && c.course_bias_sigma_rad > 0.0) {
    std::snprintf(b, sizeof b, "; course over ground %.1f +- %.1f deg (%d epochs)", rad_to_deg(c.course_bias_rad),
                  rad_to_deg(c.course_bias_sigma_rad), c.course_epochs);
    out += b;
  }
  if (c.speed_epochs > 0 && c.speed_scale_sigma > 0.0) {
    std::snprintf(b, sizeof b, "; GNSS speed scale %.3f +- %.3f (%d epochs)", c.speed_scale, c.speed_scale_sigma,
                  c.speed_epochs);
    out += b;
  }
  if (c.valid && !c.positions_used) out += "; positions not used (baseline below the minimum)";
  return out;
}

bool is_gnss(const Sample& s) { return std::holds_alternative<GnssRawSample>(s) || std::holds_alternative<FixSample>(s); }


std::string f1(double v) { return fixed_or(v, 1, "nan"); }
std::string f3(double v) { return fixed_or(v, 3, "nan"); }

fusion::NavigatorConfig make_config(const EvalOutageArgs& a, fusion::EngineMode mode,
                                    const std::shared_ptr<const terrain::Dem>& dem,
                                    const std::shared_ptr<const route::WalkGraph>& graph,
                                    const std::shared_ptr<const gnss::EphemerisStore>& eph) {
  fusion::NavigatorConfig c;
  c.mode = mode;
  c.dem = dem;
  c.graph = graph;
  c.ephemeris = eph;
  c.user_height_m = a.height_m;
  c.mount = pdr::mount_from_string(a.mount);
  apply_fusion_model(a.fusion_model, c.fusion);
  return c;
}

/// Replays `samples` with GNSS dropped in [w0, w1); records the shown estimate at each reference
/// epoch (refs sorted by time). With dr_start set (mode dr), the Navigator is restarted there at
/// the first sample at or after w0.
Track replay(const std::vector<Sample>& samples, const fusion::NavigatorConfig& cfg, std::uint64_t seed,
             const std::vector<RefPoint>& refs, const geo::LocalFrame& frame, TimeNs w0, TimeNs w1,
             const RefPoint* dr_start, ProgressBar* progress, fusion::PdrCalibration* cal_before,
             fusion::PdrCalibration* fit_before,
             std::int64_t* removed_raw, std::int64_t* removed_fix) {
  fusion::Navigator nav(cfg, seed);
  Track tr;
  tr.valid.assign(refs.size(), false);
  tr.en_m.assign(refs.size(), Eigen::Vector2d(kNaNd, kNaNd));
  tr.cov.assign(refs.size(), Eigen::Matrix2d::Constant(kNaNd));
  tr.mode.assign(refs.size(), "");
  std::size_t k = 0;
  bool restarted = dr_start == nullptr;
  bool cal_taken = false;
  auto record_until = [&](TimeNs t) {
    while (k < refs.size() && refs[k].t_ns <= t) {
      const Estimate e = nav.estimate();
      const bool ok = e.valid() && e.cov_en_m2.allFinite() && (dr_start == nullptr || restarted);
      if (ok) {
        tr.valid[k] = true;
        tr.en_m[k] = frame.to_enu(e.position).p_m.head<2>();
        tr.cov[k] = e.cov_en_m2;
        tr.mode[k] = dr_start ? "dr" : fusion::to_string(nav.output(0).mode);
      }
      ++k;
    }
  };
  const std::size_t n = samples.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Sample& s = samples[i];
    const TimeNs t = sample_time_ns(s);
    // estimates at reference epochs strictly before this sample's time
    record_until(t - 1);
    if (!cal_taken && t >= w0) {
      if (cal_before) *cal_before = nav.output(0).calibration;
      if (fit_before) *fit_before = nav.output(0).calibration_fit;
      cal_taken = true;
    }
    if (!restarted && t >= w0) {
      nav.set_start(dr_start->p.lat_deg(), dr_start->p.lon_deg(), std::max(1.0, dr_start->sigma_m), t);
      restarted = true;
    }
    if (t >= w0 && t < w1 && is_gnss(s)) {
      if (removed_raw && std::holds_alternative<GnssRawSample>(s)) ++*removed_raw;
      if (removed_fix && std::holds_alternative<FixSample>(s)) ++*removed_fix;
      continue;
    }
    nav.feed(s);
    if (progress && (i & 4095) == 0) progress->update(static_cast<double>(i) / static_cast<double>(n));
  }
  nav.finish();
  record_until(std::numeric_limits<TimeNs>::max());
  return tr;
}

/// What the outage window is cut from: the GNSS span, or (a recording without GNSS) the span of
/// its reference positions, with nothing to remove.
std::string span_label(bool gnss_in_log) {
  return gnss_in_log ? "GNSS span" : "reference span (no GNSS in the recording: nothing to remove)";
}

WalkResult evaluate(const std::string& path, const EvalOutageArgs& a, const std::shared_ptr<const terrain::Dem>& dem,
                    const std::shared_ptr<const route::WalkGraph>& graph,
                    const std::shared_ptr<const gnss::EphemerisStore>& eph, const std::filesystem::path* out_dir,
                    const std::string& tag) {
  WalkResult r;
  r.name = std::filesystem::path(path).filename().string() + tag;
  // ---- read the recording ----
  std::vector<Sample> samples;
  std::vector<RefPoint> fixes, truth;
  TimeNs g0 = -1, g1 = -1;
  {
    const std::unique_ptr<io::SampleSource> source = open_source(path, a.format);
    io::SampleSource& reader = *source;
    ProgressBar progress(a.quiet ? nullptr : &std::cerr, "eval-outage: reading " + r.name);
    Sample s;
    while (reader.next(s)) {
      const TimeNs t = sample_time_ns(s);
      if (const auto* f = std::get_if<FixSample>(&s); f && is_gps_reference_fix(*f))
        fixes.push_back({t, geo::Geodetic::from_deg(f->lat_deg, f->lon_deg, 0.0), fix_sigma_m(*f)});
      if (const auto* tr = std::get_if<TruthSample>(&s); tr && std::isfinite(tr->lat_deg) && std::isfinite(tr->lon_deg))
        truth.push_back({t, geo::Geodetic::from_deg(tr->lat_deg, tr->lon_deg, 0.0), 0.0});
      if (is_gnss(s)) {
        if (g0 < 0 || t < g0) g0 = t;
        g1 = std::max(g1, t);
      }
      samples.push_back(std::move(s));
      if ((samples.size() & 4095) == 0) progress.update(reader.progress());
    }
    progress.done();
    if (reader.stats().skipped_total() > 0)
      std::cerr << "eval-outage: " << path << ": " << reader.stats().skipped_total() << " lines skipped by the reader\n";
  }
  std::stable_sort(samples.begin(), samples.end(),
                   [](const Sample& x, const Sample& y) { return sample_time_ns(x) < sample_time_ns(y); });
  auto by_t = [](const RefPoint& x, const RefPoint& y) { return x.t_ns < y.t_ns; };
  std::stable_sort(fixes.begin(), fixes.end(), by_t);
  std::stable_sort(truth.begin(), truth.end(), by_t);
  const std::vector<RefPoint>& refs = truth.empty() ? fixes : truth;
  r.reference = truth.empty() ? "fixes" : "truth";
  if (refs.size() < 2)
    throw std::runtime_error(path + ": no reference to score against (needs GPS Fix rows or Truth rows; found " +
                             std::to_string(fixes.size()) + " fixes, " + std::to_string(truth.size()) + " truth rows)");
  if (g0 < 0) {  // no GNSS at all: the span of the reference
    g0 = refs.front().t_ns;
    g1 = refs.back().t_ns;
    r.gnss_in_log = false;
  }
  const double span_s = static_cast<double>(g1 - g0) * 1e-9;
  r.span_s = span_s;
  double w0_s = std::isfinite(a.start_s) ? a.start_s : a.start_frac * span_s;
  double len_s = std::isfinite(a.length_s) ? a.length_s : std::min(a.length_frac * span_s, a.max_s);
  const std::string span_name = span_label(r.gnss_in_log);
  if (!(w0_s >= 0.0) || !(len_s > 0.0) || w0_s + len_s > span_s + 1e-9)
    throw std::runtime_error(path + ": outage window " + f1(w0_s) + "-" + f1(w0_s + len_s) + " s is not inside the " +
                             span_name + " 0-" + f1(span_s) + " s");
  r.w0_s = w0_s;
  r.w1_s = w0_s + len_s;
  const TimeNs w0 = g0 + static_cast<TimeNs>(w0_s * 1e9), w1 = g0 + static_cast<TimeNs>(r.w1_s * 1e9);

  // ---- where dead reckoning restarts: the last phone fix before the window ----
  RefPoint dr_start;
  bool have_start = false;
  for (const RefPoint& f : fixes)
    if (f.t_ns < w0) dr_start = f, have_start = true;
  const geo::LocalFrame frame(refs.front().p);

  ProgressBar progress(a.quiet ? nullptr : &std::cerr, "eval-outage: " + r.name);
  const Track fused = replay(samples, make_config(a, fusion::EngineMode::kAuto, dem, graph, eph), a.seed, refs, frame, w0,
                             w1, nullptr, &progress, &r.cal, &r.cal_fit, &r.removed_raw, &r.removed_fix);
  if (!have_start) {
    // Raw-only log (no Fix rows): what the phone knew at the window start is the fused estimate
    for (std::size_t k = 0; k < refs.size() && refs[k].t_ns < w0; ++k)
      if (fused.valid[k]) {
        dr_start.t_ns = refs[k].t_ns;
        dr_start.p = frame.to_geodetic(geo::Enu(fused.en_m[k].x(), fused.en_m[k].y(), 0.0));
        dr_start.sigma_m = std::sqrt(0.5 * fused.cov[k].trace());
        have_start = true;
      }
  }
  if (!have_start) throw std::runtime_error(path + ": no fix (and no fused estimate) before the outage window to start from");
  r.dr_start_sigma_m = dr_start.sigma_m;
  const Track dr = replay(samples, make_config(a, fusion::EngineMode::kDeadReckoning, dem, graph, eph), a.seed, refs, frame,
                          w0, w1, &dr_start, &progress, nullptr, nullptr, nullptr, nullptr);
  progress.done();

  // ---- scores inside the window ----
  double s_f = 0, s_d = 0;
  int n_f = 0, n_d = 0;
  std::vector<Eigen::Vector2d> ref_en(refs.size());
  for (std::size_t k = 0; k < refs.size(); ++k) ref_en[k] = frame.to_enu(refs[k].p).p_m.head<2>();
  std::vector<double> m2(refs.size(), kNaNd), m2_window;
  for (std::size_t k = 0; k < refs.size(); ++k) {
    if (fused.valid[k]) {
      const Eigen::Vector2d e = fused.en_m[k] - ref_en[k];
      const Eigen::Matrix2d c = fused.cov[k] + refs[k].sigma_m * refs[k].sigma_m * Eigen::Matrix2d::Identity();
      if (c.determinant() > 0.0) m2[k] = mahalanobis2(c, e);
    }
    if (refs[k].t_ns < w0 || refs[k].t_ns >= w1) continue;
    ++r.epochs_in_window;
    if (fused.valid[k]) {
      const double e = (fused.en_m[k] - ref_en[k]).norm();
      s_f += e * e, ++n_f, r.fused_end_m = e;
      if (std::isfinite(m2[k]) && m2[k] <= kOneSigmaM2) ++r.covered;
      m2_window.push_back(m2[k]);  // (NaN: no positive definite covariance, outside, as above)
    }
    if (dr.valid[k]) {
      const double e = (dr.en_m[k] - ref_en[k]).norm();
      s_d += e * e, ++n_d, r.dr_end_m = e;
    }
  }
  r.median_m2 = median_mahalanobis2(std::move(m2_window));
  r.median_percentile = chi2_2dof_percent(r.median_m2);
  if (n_f > 0) r.fused_rms_m = std::sqrt(s_f / n_f);
  if (n_d > 0) r.dr_rms_m = std::sqrt(s_d / n_d);
  r.ratio = r.fused_rms_m / r.dr_rms_m;
  // ---- the largest shown jump when GNSS returns: consecutive reference epochs from the last in
  // the window to kJumpAfterS after it, the shown move beyond the reference's own move, in sigma
  // of the two estimates' combined covariance (as eval-fusion) ----
  for (std::size_t k = 1; k < refs.size(); ++k) {
    if (refs[k].t_ns < w1 || refs[k].t_ns > w1 + static_cast<TimeNs>(kJumpAfterS * 1e9)) continue;
    if (!fused.valid[k] || !fused.valid[k - 1]) continue;
    const Eigen::Vector2d d = (fused.en_m[k] - fused.en_m[k - 1]) - (ref_en[k] - ref_en[k - 1]);
    const Eigen::Matrix2d c = fused.cov[k] + fused.cov[k - 1];
    const double m = mahalanobis2(c, d);
    const double j = std::isfinite(m) ? std::sqrt(std::max(0.0, m)) : 1e9;
    if (j > r.max_jump_sigma) r.max_jump_sigma = j, r.max_jump_t_s = static_cast<double>(refs[k].t_ns - g0) * 1e-9;
  }

  // ---- per-walk CSV and JSON for plotting ----
  if (out_dir) {
    const std::filesystem::path stem = *out_dir / (std::filesystem::path(path).stem().string() + tag);
    std::ofstream csv(stem.string() + ".csv");
    csv << "t_s,in_window,ref_e_m,ref_n_m,ref_sigma_m,fused_e_m,fused_n_m,fused_cov_ee_m2,fused_cov_en_m2,fused_cov_nn_m2,"
           "fused_mode,dr_e_m,dr_n_m,dr_cov_ee_m2,dr_cov_en_m2,dr_cov_nn_m2,fused_err_m,dr_err_m,fused_mahalanobis2\n";
    char b[512];
    for (std::size_t k = 0; k < refs.size(); ++k) {
      const bool in = refs[k].t_ns >= w0 && refs[k].t_ns < w1;
      const double ef = fused.valid[k] ? (fused.en_m[k] - ref_en[k]).norm() : kNaNd;
      const double ed = dr.valid[k] ? (dr.en_m[k] - ref_en[k]).norm() : kNaNd;
      std::snprintf(b, sizeof b, "%.3f,%d,%.3f,%.3f,%.3f,%.3f,%.3f,%.4f,%.4f,%.4f,%s,%.3f,%.3f,%.4f,%.4f,%.4f,%.3f,%.3f,%.4f\n",
                    static_cast<double>(refs[k].t_ns - g0) * 1e-9, in ? 1 : 0, ref_en[k].x(), ref_en[k].y(), refs[k].sigma_m,
                    fused.en_m[k].x(), fused.en_m[k].y(), fused.cov[k](0, 0), fused.cov[k](0, 1), fused.cov[k](1, 1),
                    fused.mode[k].empty() ? "-" : fused.mode[k].c_str(), dr.en_m[k].x(), dr.en_m[k].y(), dr.cov[k](0, 0),
                    dr.cov[k](0, 1), dr.cov[k](1, 1), ef, ed, m2[k]);
      csv << b;
    }
    nlohmann::json j;
    j["log"] = path;
    j["reference"] = r.reference;
    j["gnss_span_s"] = span_s;
    j["gnss_in_log"] = r.gnss_in_log;
    j["window_s"] = {r.w0_s, r.w1_s};
    j["epochs_in_window"] = r.epochs_in_window;
    j["removed"] = {{"raw_rows", r.removed_raw}, {"fix_rows", r.removed_fix}};
    j["fused"] = {{"rms_m", r.fused_rms_m}, {"end_m", r.fused_end_m}};
    j["dr"] = {{"rms_m", r.dr_rms_m}, {"end_m", r.dr_end_m}, {"start_sigma_m", r.dr_start_sigma_m}};
    j["outage_ratio"] = r.ratio;
    j["coverage_68"] = r.epochs_in_window > 0 ? static_cast<double>(r.covered) / r.epochs_in_window : kNaNd;
    j["median_mahalanobis2"] = r.median_m2;
    j["median_percentile"] = r.median_percentile;
    j["max_jump_sigma"] = r.max_jump_sigma;
    j["calibration_before_window"] = pdr_calibration_json(r.cal);
    j["calibration_fit_before_window"] = pdr_calibration_json(r.cal_fit);
    std::ofstream(stem.string() + ".json") << j.dump(2) << "\n";
  }
  return r;
}

int run_eval_outage(const EvalOutageArgs& a) {
  const auto t0 = std::chrono::steady_clock::now();
  if (std::isfinite(a.start_s) != std::isfinite(a.length_s))
    throw std::invalid_argument("--start-s and --length-s go together");
  if (std::isfinite(a.start_s) && !a.start_fracs.empty())
    throw std::invalid_argument("--start-fracs and --start-s exclude each other");
  const std::vector<double> starts = a.start_fracs.empty() ? std::vector<double>{a.start_frac} : a.start_fracs;
  for (double f : starts)
    if (!std::isfinite(a.start_s) && !(f >= 0.0 && a.length_frac > 0.0 && f + a.length_frac <= 1.0 && a.max_s > 0.0))
      throw std::invalid_argument("need 0 <= --start-frac (each of --start-fracs), 0 < --length-frac, their sum <= 1, "
                                  "--max-s > 0 (start " + f3(f) + ")");
  std::shared_ptr<const terrain::Dem> dem;
  std::shared_ptr<const route::WalkGraph> graph;
  std::shared_ptr<const gnss::EphemerisStore> eph;
  if (!a.dem.empty()) dem = std::make_shared<const terrain::Dem>(terrain::Dem::load(a.dem));
  if (!a.graph.empty()) graph = std::make_shared<const route::WalkGraph>(route::WalkGraph::load(a.graph));
  if (!a.nav.empty()) {
    auto e = std::make_shared<gnss::EphemerisStore>();
    for (const std::string& p : a.nav) e->load_rinex_nav(p);
    eph = e;
  }
  std::filesystem::path out;
  if (!a.out_dir.empty()) std::filesystem::create_directories(out = a.out_dir);
  std::printf("eval-outage: %zu recording(s); window %s; GNSS (Raw and Fix) removed in it; fused (auto) vs dead "
              "reckoning restarted at the last fix before it (uncalibrated PDR)\n",
              a.logs.size(),
              std::isfinite(a.start_s)
                  ? ("from " + f1(a.start_s) + " s for " + f1(a.length_s) + " s of the GNSS span").c_str()
                  : ("from " + (starts.size() == 1 ? f3(starts[0]) : std::to_string(starts.size()) + " starts " +
                                f3(starts.front()) + ".." + f3(starts.back())) +
                     " of the GNSS span for " + f3(a.length_frac) + " of it, at most " + f1(a.max_s) + " s").c_str());
  std::vector<WalkResult> results;
  for (const std::string& log : a.logs)
  for (double start : starts) {
    EvalOutageArgs b = a;
    b.start_frac = start;
    const std::string tag = a.start_fracs.empty() ? "" : "@" + f3(start).substr(0, 4);
    WalkResult r = evaluate(log, b, dem, graph, eph, out.empty() ? nullptr : &out, tag);
    const double cov = r.epochs_in_window > 0 ? static_cast<double>(r.covered) / r.epochs_in_window : kNaNd;
    std::printf("%s: reference %s, %s %.0f s, window %.0f-%.0f s (%d epochs; removed %lld Raw, %lld Fix rows)\n",
                r.name.c_str(), r.reference.c_str(),
                span_label(r.gnss_in_log).c_str(), r.span_s,
                r.w0_s, r.w1_s, r.epochs_in_window,
                static_cast<long long>(r.removed_raw), static_cast<long long>(r.removed_fix));
    std::printf("  fused: rms %s m, end %s m | dr: rms %s m, end %s m (start sigma %s m) | ratio %s | coverage_68 %s | "
                "max jump %s sigma (at %s s)\n",
                f1(r.fused_rms_m).c_str(), f1(r.fused_end_m).c_str(), f1(r.dr_rms_m).c_str(), f1(r.dr_end_m).c_str(),
                f1(r.dr_start_sigma_m).c_str(), f3(r.ratio).c_str(), f3(cov).c_str(), f3(r.max_jump_sigma).c_str(),
                f1(r.max_jump_t_s).c_str());
    std::printf("  the window's median error is at the %s percentile of the stated distribution (median squared "
                "Mahalanobis distance %s; 50 = calibrated, one window is one draw)\n",
                f1(r.median_percentile).c_str(), f3(r.median_m2).c_str());
    if (r.cal.valid)
      std::printf("  calibration published before the window: scale %.3f +- %.3f, heading bias %.1f +- %.1f deg, %d epochs, "
                  "baseline %.0f m%s\n",
                  r.cal.scale, r.cal.scale_sigma, rad_to_deg(r.cal.heading_bias_rad), rad_to_deg(r.cal.heading_bias_sigma_rad),
                  r.cal.epochs, r.cal.baseline_m, calibration_note(r.cal).c_str());
    else
      std::printf("  calibration published before the window: none (uncalibrated PDR in the window); last fit: scale "
                  "%.3f +- %.3f, heading bias %.1f +- %.1f deg, %d epochs, baseline %.0f m, residual autocorrelation time %.1f epochs%s\n",
                  r.cal_fit.scale, r.cal_fit.scale_sigma, rad_to_deg(r.cal_fit.heading_bias_rad),
                  rad_to_deg(r.cal_fit.heading_bias_sigma_rad), r.cal_fit.epochs, r.cal_fit.baseline_m, r.cal_fit.residual_tau,
                  calibration_note(r.cal_fit).c_str());
    std::fflush(stdout);
    results.push_back(r);
  }
  std::vector<double> ratio, rms, percentile;
  int covered = 0, epochs = 0;
  double jump = 0.0;
  for (const WalkResult& r : results) {
    ratio.push_back(r.ratio);
    rms.push_back(r.fused_rms_m);
    percentile.push_back(r.median_percentile);
    covered += r.covered;
    epochs += r.epochs_in_window;
    jump = std::max(jump, r.max_jump_sigma);
  }
  const double run_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("window_median_percentile: %s (median over the windows of where each one's median error falls in its "
              "stated distribution; 50 = calibrated)\n",
              f1(median_of_finite(percentile)).c_str());
  std::printf("run_time_s: %.1f%s\n", run_s, out.empty() ? "" : (" per-walk CSV/JSON: " + out.string()).c_str());
  std::printf("outage_ratio: %s outage_rms_m: %s coverage_68: %s max_jump_sigma: %s walks: %zu\n",
              f3(median_of_finite(ratio)).c_str(), f1(median_of_finite(rms)).c_str(),
              f3(epochs > 0 ? static_cast<double>(covered) / epochs : kNaNd).c_str(), f3(jump).c_str(), results.size());
  return 0;
}

}  // namespace

void register_eval_outage(CLI::App& app) {
  auto a = std::make_shared<EvalOutageArgs>();
  CLI::App* c = app.add_subcommand(
      "eval-outage",
      "Cut a GNSS outage into recordings and score the fused estimate in it against the withheld fixes (or Truth) vs "
      "dead reckoning restarted at the last fix");
  c->add_option("logs", a->logs,
                "recordings: session or GnssLogger logs, Sensor Logger / phyphox folders or zips, GetSensorData files")
      ->required()->check(CLI::ExistingPath);
  add_format_option(c, a->format);
  c->add_option("--start-frac", a->start_frac, "window start, fraction of the GNSS span")->capture_default_str();
  c->add_option("--length-frac", a->length_frac, "window length, fraction of the GNSS span")->capture_default_str();
  c->add_option("--max-s", a->max_s, "longest window, s")->capture_default_str();
  c->add_option("--start-fracs", a->start_fracs,
                 "several windows per recording (a sweep; comma-separated starts, fractions of the GNSS span): each "
                 "(recording, window) is one walk of the summary line")
      ->delimiter(',');
  c->add_option("--start-s", a->start_s, "window start, s from the start of the GNSS span (with --length-s)");
  c->add_option("--length-s", a->length_s, "window length, s (with --start-s)");
  c->add_option("--dem", a->dem, "DEM tile (.pdem) for the terrain engine")->check(CLI::ExistingFile);
  c->add_option("--graph", a->graph, "walkway graph for the route engine")->check(CLI::ExistingFile);
  c->add_option("--nav", a->nav, "RINEX navigation file(s) for Raw GNSS")->check(CLI::ExistingFile);
  c->add_option("--out", a->out_dir, "directory for per-walk CSV + JSON (tools/plot.py outage DIR)");
  c->add_option("--mount", a->mount, "phone placement (as pdnav replay)")->capture_default_str();
  c->add_option("--height", a->height_m, "user height, m (default: the log's, else unknown)");
  c->add_option("--seed", a->seed, "random seed")->capture_default_str();
  add_fusion_model_option(c, a->fusion_model);
  c->add_flag("--quiet", a->quiet, "no progress on stderr");
  c->callback([a]() { run_eval_outage(*a); });
}

}  // namespace pdnav::cli