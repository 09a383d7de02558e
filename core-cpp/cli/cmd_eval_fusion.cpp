// pdnav eval-fusion: simulated phone sessions with a GNSS outage (phonesim), each written
// through io::LogWriter, read back with io::LogReader and replayed through fusion::Navigator
// exactly as `pdnav replay` does; fused (auto) vs dead reckoning from the outage start,
// GNSS-only, terrain-only and route-only. Metric definitions: docs/simulator.md "eval-fusion".
#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <cstdio>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "pdnav/fusion/navigator.h"
#include "pdnav/gnss/ephemeris.h"
#include "pdnav/io/log_reader.h"
#include "pdnav/io/log_writer.h"
#include "pdnav/phonesim/phone_session.h"
#include "pdnav/route/walk_graph.h"
#include "pdnav/terrain/dem.h"
#include "pdnav/terrain/simulator.h"
#include "support/eval_support.h"

namespace pdnav::cli {
namespace {

constexpr double kNaNd = std::numeric_limits<double>::quiet_NaN();
constexpr TimeNs kReacquireHoldNs = 30 * kNsPerS;  // reacquire_s: the condition must hold this long

struct EvalFusionArgs {
  std::string dem, graph;
  std::vector<std::string> nav;
  int walks = 20;
  std::uint64_t seed = 1;
  double outage_min_min = 2.0, outage_max_min = 20.0;
  double lead_s = 360.0, tail_s = 180.0;
  int particles = 500;
  bool quiet = false;
  std::string fusion_model = "issue28";
};

/// Navigator estimates at the truth epochs, in the DEM frame.
struct Track {
  std::vector<bool> valid;
  std::vector<Eigen::Vector2d> en_m;
  std::vector<Eigen::Matrix2d> cov;
  std::map<std::string, std::int64_t> counts;  // the Navigator's fusion counts at the end
};

/// The session through the log writer and reader (in memory, the same text as a file).
std::vector<Sample> through_log(const std::vector<Sample>& samples, std::size_t* skipped) {
  auto buf = std::make_shared<std::stringbuf>();
  {
    io::LogWriterOptions wo;
    wo.device = "pdnav eval-fusion";
    io::LogWriter writer(std::make_unique<std::ostream>(buf.get()), "eval-fusion session", wo);
    for (const Sample& s : samples) writer.write(s);
    writer.close();
  }
  io::LogReader reader(std::make_unique<std::istringstream>(buf->str()), "eval-fusion session");
  std::vector<Sample> out;
  out.reserve(samples.size());
  Sample s;
  while (reader.next(s)) out.push_back(s);
  *skipped = static_cast<std::size_t>(reader.stats().skipped_total());
  return out;
}

/// Replays `samples` through a Navigator in `mode`, recording its estimate after each Truth
/// row. With start_t_ns >= 0 the Navigator sees only Meta rows before that time and is started
/// there at `start` (lat, lon, sigma).
Track replay(const std::vector<Sample>& samples, const fusion::NavigatorConfig& base, fusion::EngineMode mode,
             std::uint64_t seed, const terrain::Dem& dem, std::size_t n_truth, TimeNs start_t_ns = -1,
             const Eigen::Vector3d& start = Eigen::Vector3d::Zero()) {
  fusion::NavigatorConfig cfg = base;
  cfg.mode = mode;
  fusion::Navigator nav(cfg, seed);
  Track tr;
  tr.valid.reserve(n_truth);
  bool started = start_t_ns < 0;
  for (const Sample& s : samples) {
    const TimeNs t = sample_time_ns(s);
    const bool is_truth = std::holds_alternative<TruthSample>(s);
    if (!started) {
      if (std::holds_alternative<MetaSample>(s)) nav.feed(s);
      if (t >= start_t_ns) {
        nav.set_start(start.x(), start.y(), start.z(), t);
        started = true;
      }
    }
    if (started) nav.feed(s);
    if (is_truth) {
      const Estimate e = nav.estimate();
      const bool ok = started && e.valid() && e.en_m.allFinite() && e.cov_en_m2.allFinite();
      tr.valid.push_back(ok);
      tr.en_m.push_back(ok ? dem.to_local(e.position) : Eigen::Vector2d(kNaNd, kNaNd));
      tr.cov.push_back(e.cov_en_m2);
    }
  }
  for (const auto& [what, n] : nav.fusion_counts()) tr.counts[what] = n;
  return tr;
}

struct Drms {
  double drms_m = kNaNd;
  double valid_fraction = 0.0;
};

Drms drms(const Track& t, const std::vector<phonesim::TruthPoint>& truth, const std::vector<std::size_t>& idx) {
  Drms d;
  double sum = 0.0;
  std::size_t n = 0;
  for (const std::size_t k : idx) {
    if (k >= t.valid.size() || !t.valid[k]) continue;
    sum += (t.en_m[k] - truth[k].en_m).squaredNorm();
    ++n;
  }
  if (n > 0) d.drms_m = std::sqrt(sum / static_cast<double>(n));
  d.valid_fraction = idx.empty() ? 0.0 : static_cast<double>(n) / static_cast<double>(idx.size());
  return d;
}

/// Scale and rotation of the estimated track against the truth over the epochs idx
/// (2-D Procrustes: b ~ z a with complex z = s e^{i theta}); heading error clockwise, deg.
std::pair<double, double> track_calibration(const Track& t, const std::vector<phonesim::TruthPoint>& truth,
                                            const std::vector<std::size_t>& idx) {
  std::size_t first = idx.size();
  for (std::size_t i = 0; i < idx.size(); ++i)
    if (idx[i] < t.valid.size() && t.valid[idx[i]]) { first = i; break; }
  if (first == idx.size()) return {kNaNd, kNaNd};
  const std::size_t k0 = idx[first];
  std::complex<double> num(0, 0);
  double den = 0.0;
  for (std::size_t i = first + 1; i < idx.size(); ++i) {
    const std::size_t k = idx[i];
    if (k >= t.valid.size() || !t.valid[k]) continue;
    const Eigen::Vector2d a = truth[k].en_m - truth[k0].en_m, b = t.en_m[k] - t.en_m[k0];
    const std::complex<double> ca(a.x(), a.y()), cb(b.x(), b.y());
    num += std::conj(ca) * cb;
    den += std::norm(ca);
  }
  if (!(den > 100.0)) return {kNaNd, kNaNd};
  const std::complex<double> z = num / den;
  return {std::abs(z) - 1.0, -std::arg(z) * kRadToDeg};
}

struct WalkResult {
  std::uint64_t seed = 0;
  double length_m = 0, outage_s = 0;
  Drms out[5], after[5], open[5];  // fused, dr, gnss, terrain, route
  double outage_ratio = kNaNd, open_sky_ratio = kNaNd, max_jump_sigma = 0.0, reacquire_s = kNaNd;
  double gnss_back_s = kNaNd;  // GNSS-only valid again this long after the scripted outage's end
  int out_covered_68 = 0, out_scored = 0;  // outage epochs with truth inside the fused 68 % region / scored
  // the outage's median squared Mahalanobis distance as a chi^2(2) percentile (50 = calibrated):
  // one outage's error is correlated over minutes, its coverage near 0 or 1 (as eval-outage)
  double out_median_percentile = kNaNd;
  bool reacquire_censored = false;
  std::pair<double, double> cal_dr{kNaNd, kNaNd}, cal_fused{kNaNd, kNaNd};
  phonesim::SessionStats stats;
  std::size_t skipped_lines = 0;
  std::int64_t route_scale_used = 0, route_scale_rejected = 0;  // the map's step-scale samples in the fused replay
};

WalkResult evaluate(const phonesim::PhoneSession& ses, const fusion::NavigatorConfig& base, const terrain::Dem& dem,
                    std::uint64_t seed) {
  WalkResult r;
  r.seed = ses.seed;
  r.stats = ses.stats;
  r.length_m = ses.stats.length_m;
  r.outage_s = ns_to_s(ses.outage_end_ns - ses.outage_start_ns);
  const std::vector<Sample> samples = through_log(ses.samples, &r.skipped_lines);
  const auto& truth = ses.truth;
  const std::size_t n = truth.size();

  const Track fused = replay(samples, base, fusion::EngineMode::kAuto, seed, dem, n);
  const Track gnss = replay(samples, base, fusion::EngineMode::kGnss, seed, dem, n);
  // The engines on their own start at the outage from what the phone knew then: the
  // GNSS-only estimate at the outage start (its 1-sigma), dead reckoning with uncalibrated PDR.
  std::size_t k_out = 0;
  while (k_out < n && truth[k_out].t_ns < ses.outage_start_ns) ++k_out;
  std::size_t k_known = k_out;
  while (k_known > 0 && !(k_known < gnss.valid.size() && gnss.valid[k_known])) --k_known;
  Eigen::Vector2d start_en = k_known < gnss.valid.size() && gnss.valid[k_known] ? gnss.en_m[k_known] : truth[0].en_m;
  const double start_sigma =
      k_known < gnss.cov.size() ? std::max(1.0, std::sqrt(std::max(0.0, 0.5 * gnss.cov[k_known].trace()))) : 5.0;
  const geo::Geodetic sg = dem.to_geodetic(start_en.x(), start_en.y());
  const Eigen::Vector3d start(sg.lat_deg(), sg.lon_deg(), start_sigma);
  const Track dr = replay(samples, base, fusion::EngineMode::kDeadReckoning, seed, dem, n, ses.outage_start_ns, start);
  const Track terr = base.dem ? replay(samples, base, fusion::EngineMode::kTerrain, seed, dem, n, ses.outage_start_ns, start) : Track{};
  const Track route = base.graph ? replay(samples, base, fusion::EngineMode::kRoute, seed, dem, n, ses.outage_start_ns, start) : Track{};
  const Track* tracks[5] = {&fused, &dr, &gnss, &terr, &route};

  std::vector<std::size_t> out_idx, after_idx, open_idx;
  const TimeNs t_first = truth.empty() ? 0 : truth.front().t_ns;
  for (std::size_t k = 0; k < n; ++k) {
    const TimeNs t = truth[k].t_ns;
    if (truth[k].outage) out_idx.push_back(k);
    else if (t >= ses.outage_end_ns) after_idx.push_back(k);
    const bool warm = t - t_first >= 60 * kNsPerS;
    const bool settling = t >= ses.outage_end_ns && t < ses.outage_end_ns + 30 * kNsPerS;
    if (!truth[k].outage && !truth[k].degraded && warm && !settling) open_idx.push_back(k);
  }
  for (int e = 0; e < 5; ++e) {
    r.out[e] = drms(*tracks[e], truth, out_idx);
    r.after[e] = drms(*tracks[e], truth, after_idx);
    r.open[e] = drms(*tracks[e], truth, open_idx);
  }
  r.outage_ratio = r.out[0].drms_m / r.out[1].drms_m;
  // Consistency of the fused covariance in the outage: truth inside its 68.27 % ellipse
  // (Mahalanobis^2 <= kOneSigmaM2; docs/results.md "Coverage definitions").
  std::vector<double> out_m2;
  for (const std::size_t k : out_idx) {
    if (k >= fused.valid.size() || !fused.valid[k]) continue;
    ++r.out_scored;
    const double m2 = mahalanobis2(fused.cov[k], fused.en_m[k] - truth[k].en_m);
    if (std::isfinite(m2) && m2 <= kOneSigmaM2) ++r.out_covered_68;
    out_m2.push_back(m2);
  }
  r.out_median_percentile = chi2_2dof_percent(median_mahalanobis2(std::move(out_m2)));
  r.open_sky_ratio = r.open[0].drms_m / r.open[2].drms_m;
  // Largest jump of the shown position between consecutive epochs, beyond the true motion,
  // in sigma of the two epochs' combined covariance.
  for (std::size_t k = 1; k < n; ++k) {
    if (!fused.valid[k] || !fused.valid[k - 1]) continue;
    const Eigen::Vector2d d = (fused.en_m[k] - fused.en_m[k - 1]) - (truth[k].en_m - truth[k - 1].en_m);
    const double m2 = mahalanobis2(fused.cov[k] + fused.cov[k - 1], d);
    r.max_jump_sigma = std::max(r.max_jump_sigma, std::isfinite(m2) ? std::sqrt(m2) : 1e9);
  }
  // Re-convergence: first epoch after GNSS returns from which, for 30 s (or to the walk's end),
  // the fused error stays within 2x the GNSS-only error. (A short hold would be met trivially in
  // the first seconds, while the GNSS-only filter itself still coasts on its outage prediction.)
  // GNSS returns at the first epoch after the scripted outage at which the GNSS-only engine has
  // a valid estimate (the sky may stay masked for a while after the script's end); an epoch
  // without one has nothing to compare with and is passed over.
  auto ok_at = [&](std::size_t k) {
    if (!gnss.valid[k]) return true;
    return fused.valid[k] && (fused.en_m[k] - truth[k].en_m).norm() <= 2.0 * (gnss.en_m[k] - truth[k].en_m).norm();
  };
  std::size_t back = 0;
  while (back < after_idx.size() && !gnss.valid[after_idx[back]]) ++back;
  if (back < after_idx.size()) {
    r.gnss_back_s = ns_to_s(truth[after_idx[back]].t_ns - ses.outage_end_ns);
    const TimeNs back_ns = truth[after_idx[back]].t_ns;
    for (std::size_t i = back; i < after_idx.size() && !std::isfinite(r.reacquire_s); ++i) {
      bool hold = true;
      for (std::size_t j = i; j < after_idx.size() && truth[after_idx[j]].t_ns <= truth[after_idx[i]].t_ns + kReacquireHoldNs; ++j)
        hold = hold && ok_at(after_idx[j]);
      if (hold) r.reacquire_s = ns_to_s(truth[after_idx[i]].t_ns - back_ns);
    }
    if (!std::isfinite(r.reacquire_s)) {
      r.reacquire_s = ns_to_s(truth[after_idx.back()].t_ns - back_ns);
      r.reacquire_censored = true;
    }
  }
  r.cal_dr = track_calibration(dr, truth, out_idx);
  r.cal_fused = track_calibration(fused, truth, out_idx);
  const auto count = [&](const char* what) { const auto it = fused.counts.find(what); return it == fused.counts.end() ? 0 : it->second; };
  r.route_scale_used = count(fusion::Navigator::kRouteScaleUsed);
  r.route_scale_rejected = count(fusion::Navigator::kRouteScaleRejected);
  return r;
}

std::string f1(double v) { return fixed_or(v, 1, "-"); }  // '-' = no valid estimate (the table's legend)
/// A scenario's DRMS, '-' when the engine had a valid estimate at fewer than half of its epochs
/// (GNSS alone in an outage: a DRMS of the few epochs at its edges would read as its accuracy).
double scored_drms(const Drms& d) { return d.valid_fraction >= 0.5 ? d.drms_m : kNaNd; }
std::string drms_cell(const Drms& d) { return f1(scored_drms(d)); }
std::string f3(double v) { return fixed_or(v, 3, "nan"); }

int run_eval_fusion(const EvalFusionArgs& a) {
  if (a.walks < 1) throw std::invalid_argument("--walks must be >= 1");
  if (!(a.outage_min_min >= 0.0 && a.outage_max_min >= a.outage_min_min))
    throw std::invalid_argument("need 0 <= --outage-min <= --outage-max (minutes)");
  if (a.nav.empty()) throw std::invalid_argument("--nav: at least one RINEX navigation file is needed");
  const auto t0 = std::chrono::steady_clock::now();
  auto dem = std::make_shared<const terrain::Dem>(terrain::Dem::load(a.dem));
  auto graph = std::make_shared<const route::WalkGraph>(route::WalkGraph::load(a.graph));
  auto eph = std::make_shared<gnss::EphemerisStore>();
  for (const std::string& p : a.nav) eph->load_rinex_nav(p);
  std::shared_ptr<const gnss::EphemerisStore> eph_c = eph;

  fusion::NavigatorConfig base;
  base.dem = dem;
  base.graph = graph;
  base.ephemeris = eph_c;
  base.particles = a.particles;
  apply_fusion_model(a.fusion_model, base.fusion);

  phonesim::SessionOptions so;
  so.outage_min_s = 60.0 * a.outage_min_min;
  so.outage_max_s = 60.0 * a.outage_max_min;
  so.lead_s = a.lead_s;
  so.tail_s = a.tail_s;

  std::printf("eval-fusion: %d walks, seed %llu, outages %.1f-%.1f min, lead %.0f s, tail %.0f s, %d particles\n",
              a.walks, static_cast<unsigned long long>(a.seed), a.outage_min_min, a.outage_max_min, a.lead_s, a.tail_s,
              a.particles);
  std::printf("DRMS in m per scenario: fused (auto) | dr (from the outage start, uncalibrated PDR) | gnss | terrain | route "
              "(terrain/route on their own from the outage start); '-' = no valid estimate at half of the epochs or more\n");
  std::printf("%-5s %-9s %-14s %7s %7s %7s %7s %7s\n", "walk", "seed", "scenario", "fused", "dr", "gnss", "terrain", "route");
  std::vector<WalkResult> results;
  std::map<std::string, int> skipped;
  int attempts = 0;
  for (int k = 0; static_cast<int>(results.size()) < a.walks && attempts < 3 * a.walks; ++k, ++attempts) {
    const std::uint64_t ws = terrain::walk_seed(a.seed, static_cast<std::uint64_t>(k));
    if (!a.quiet) std::cerr << "eval-fusion: walk " << results.size() + 1 << "/" << a.walks << " (seed " << ws << ")\n";
    phonesim::PhoneSession ses;
    try {
      ses = phonesim::simulate_session(*dem, *graph, *eph, so, ws);
    } catch (const std::runtime_error& e) {
      ++skipped[e.what()];
      std::cerr << "eval-fusion: walk seed " << ws << " skipped: " << e.what() << "\n";
      continue;
    }
    WalkResult r = evaluate(ses, base, *dem, ws);
    const int w = static_cast<int>(results.size()) + 1;
    const char* names[3] = {"during-outage", "after-outage", "open-sky"};
    const Drms* rows[3] = {r.out, r.after, r.open};
    for (int s = 0; s < 3; ++s)
      std::printf("%-5d %-9llu %-14s %7s %7s %7s %7s %7s\n", w, static_cast<unsigned long long>(ws % 1000000000ULL),
                  names[s], drms_cell(rows[s][0]).c_str(), drms_cell(rows[s][1]).c_str(), drms_cell(rows[s][2]).c_str(),
                  drms_cell(rows[s][3]).c_str(), drms_cell(rows[s][4]).c_str());
    std::printf("      walk %d (seed %llu): %.0f m, outage %.0f s, %.1f sats; outage_ratio %s, coverage_68 in outage %s, max_jump_sigma %s, reacquire_s %s%s (GNSS alone back %s s after the outage), "
                "open_sky_ratio %s; calibration over the outage (scale err %%, heading err deg): dr %s/%s fused %s/%s; "
                "truth: stride %.3f x APT, heading bias at outage %.1f deg; map step-scale samples used %lld (refused %lld)\n",
                w, static_cast<unsigned long long>(ws), r.length_m, r.outage_s, r.stats.mean_sats_tracked, f3(r.outage_ratio).c_str(),
                f3(r.out_scored > 0 ? static_cast<double>(r.out_covered_68) / r.out_scored : kNaNd).c_str(),
                f3(r.max_jump_sigma).c_str(), f1(r.reacquire_s).c_str(), r.reacquire_censored ? " (never, censored)" : "", f1(r.gnss_back_s).c_str(),
                std::isfinite(r.open_sky_ratio) ? f3(r.open_sky_ratio).c_str()
                                                : "- (no open-sky epoch after the first 60 s, outside the outage, "
                                                  "its 30 s after and degraded spans: not in the median)",
                f1(100 * r.cal_dr.first).c_str(), f1(r.cal_dr.second).c_str(),
                f1(100 * r.cal_fused.first).c_str(), f1(r.cal_fused.second).c_str(), r.stats.walker_stride_scale,
                r.stats.heading_bias_at_outage_deg, static_cast<long long>(r.route_scale_used),
                static_cast<long long>(r.route_scale_rejected));
    if (r.skipped_lines > 0) std::printf("      walk %d: %zu log lines skipped by the reader\n", w, r.skipped_lines);
    std::fflush(stdout);
    results.push_back(r);
  }
  for (const auto& [why, cnt] : skipped) std::printf("skipped %d walks: %s\n", cnt, why.c_str());
  if (results.empty())
    throw std::runtime_error("eval-fusion: no walk could be simulated (" + std::to_string(attempts) + " seeds tried)");
  if (static_cast<int>(results.size()) < a.walks)
    throw std::runtime_error("eval-fusion: only " + std::to_string(results.size()) + " of " + std::to_string(a.walks) +
                             " walks could be simulated");
  std::vector<double> ratio, jump, reacq, open, percentile, e_out[5], e_after[5];
  int covered = 0, scored = 0;
  std::int64_t scale_used = 0, scale_refused = 0;
  for (const auto& r : results) {
    scale_used += r.route_scale_used;
    scale_refused += r.route_scale_rejected;
    covered += r.out_covered_68;
    scored += r.out_scored;
    ratio.push_back(r.outage_ratio);
    percentile.push_back(r.out_median_percentile);
    jump.push_back(r.max_jump_sigma);
    reacq.push_back(r.reacquire_s);
    open.push_back(r.open_sky_ratio);
    for (int e = 0; e < 5; ++e) e_out[e].push_back(scored_drms(r.out[e])), e_after[e].push_back(scored_drms(r.after[e]));
  }
  auto med = [](const std::vector<double>& v) { return f1(median_of_finite(v)); };
  std::printf("median DRMS during outages (m): fused %s dr %s gnss %s terrain %s route %s\n", med(e_out[0]).c_str(),
              med(e_out[1]).c_str(), med(e_out[2]).c_str(), med(e_out[3]).c_str(), med(e_out[4]).c_str());
  std::printf("median DRMS after outages (m):  fused %s dr %s gnss %s terrain %s route %s\n", med(e_after[0]).c_str(),
              med(e_after[1]).c_str(), med(e_after[2]).c_str(), med(e_after[3]).c_str(), med(e_after[4]).c_str());
  std::printf("the map's step-scale samples (two matched turns) in the fused replays: %lld used, %lld refused by the gate\n",
              static_cast<long long>(scale_used), static_cast<long long>(scale_refused));
  // the walks far from their peers, with the whole seed (the table's column is cut to 9 digits)
  // and the command that writes that session, to look at one
  std::vector<std::size_t> order(results.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  auto key = [&](std::size_t k) { return std::isfinite(results[k].outage_ratio) ? results[k].outage_ratio : -1.0; };
  std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return key(x) > key(y); });
  std::printf("worst walks by outage_ratio:");
  for (std::size_t i = 0; i < std::min<std::size_t>(3, order.size()); ++i) {
    const WalkResult& r = results[order[i]];
    std::printf("%s walk %zu (seed %llu) %s", i ? "," : "", order[i] + 1, static_cast<unsigned long long>(r.seed),
                f3(r.outage_ratio).c_str());
  }
  std::printf("\nto write one: pdnav simulate --session --seed SEED --dem %s --graph %s --nav", a.dem.c_str(), a.graph.c_str());
  for (const auto& n : a.nav) std::printf(" %s", n.c_str());
  std::printf(" --outage-min %g --outage-max %g --lead %g --tail %g -o walk.log\n", a.outage_min_min, a.outage_max_min,
              a.lead_s, a.tail_s);
  std::printf("outage_median_percentile: %s (median over the walks of where each outage's median error falls in its "
              "stated distribution; 50 = calibrated)\n",
              f1(median_of_finite(percentile)).c_str());
  const double run_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("walks: %zu run_time_s: %.1f fused coverage_68 in outages (pooled): %s\n", results.size(), run_s,
              f3(scored > 0 ? static_cast<double>(covered) / scored : kNaNd).c_str());
  const double max_jump = *std::max_element(jump.begin(), jump.end());
  std::printf("outage_ratio: %s max_jump_sigma: %s reacquire_s: %s open_sky_ratio: %s\n",
              f3(median_of_finite(ratio)).c_str(), f3(max_jump).c_str(), f3(median_of_finite(reacq)).c_str(),
              f3(median_of_finite(open)).c_str());
  return 0;
}

}  // namespace

void register_eval_fusion(CLI::App& app) {
  auto a = std::make_shared<EvalFusionArgs>();
  CLI::App* c = app.add_subcommand("eval-fusion",
                                   "Fused Navigator vs dead reckoning, GNSS, terrain and route on simulated phone "
                                   "sessions with GNSS outages, through the session log (as pdnav replay)");
  c->add_option("--dem", a->dem, "DEM tile (.pdem from dem-tools)")->required()->check(CLI::ExistingFile);
  c->add_option("--graph", a->graph, "walkway graph (from dem-tools)")->required()->check(CLI::ExistingFile);
  c->add_option("--nav", a->nav, "RINEX broadcast navigation file(s): the satellites of the simulated sky")
      ->required()->check(CLI::ExistingFile);
  c->add_option("--walks", a->walks, "number of simulated sessions")->capture_default_str();
  c->add_option("--seed", a->seed, "base random seed")->capture_default_str();
  c->add_option("--outage-min", a->outage_min_min, "shortest GNSS outage, minutes")->capture_default_str();
  c->add_option("--outage-max", a->outage_max_min, "longest GNSS outage, minutes")->capture_default_str();
  c->add_option("--lead", a->lead_s, "open-sky GNSS before the outage, s")->capture_default_str();
  c->add_option("--tail", a->tail_s, "walking after the outage, s")->capture_default_str();
  c->add_option("--particles", a->particles, "terrain particle count")->capture_default_str();
  add_fusion_model_option(c, a->fusion_model);
  c->add_flag("--quiet", a->quiet, "no progress on stderr");
  c->callback([a]() { run_eval_fusion(*a); });
}

}  // namespace pdnav::cli
