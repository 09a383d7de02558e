// Helpers of the replay command: progress bar, reference tracking, track/GeoJSON writers
// and error statistics against a reference (ground truth or the phone's GPS fixes).
#pragma once
#include <cstdint>
#include <map>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pdnav/fusion/pdr_calibrator.h"
#include "pdnav/geo/estimate.h"
#include "pdnav/geo/frames.h"
#include "pdnav/geo/samples.h"
#include "pdnav/pdr/pdr.h"

namespace pdnav::cli {

/// "1.5,2,3" -> {1.5, 2, 3}; throws std::invalid_argument naming the option on bad input.
std::vector<double> parse_number_list(const std::string& text, const std::string& what);

/// Progress on stderr: a self-rewriting line on a terminal, a line every 10 % otherwise
/// (CI logs), nothing when out is null.
class ProgressBar {
 public:
  ProgressBar(std::ostream* out, std::string label);
  void update(double fraction);
  void done();

 private:
  std::ostream* out_;
  std::string label_;
  bool tty_ = false;
  int last_percent_ = -1;
};

struct ErrorStats {
  std::int64_t n = 0;
  double drms_m = 0.0;       // sqrt(mean(e^2 + n^2))
  double rms_e_m = 0.0;
  double rms_n_m = 0.0;
  double p50_h_m = 0.0;
  double p95_h_m = 0.0;
  double coverage_1sigma = 0.0;  // inside the 1-sigma ellipse (Mahalanobis <= 1; 39.3 % if consistent)
  double coverage_68 = 0.0;      // inside the 68.27 % ellipse (Mahalanobis^2 <= kOneSigmaM2; 68.3 % if consistent)
  /// The median squared Mahalanobis distance as a chi^2(2) percentile (50 if consistent): a
  /// walk's error is correlated over minutes, so its coverage is a few draws; this says how far
  /// inside (< 50) or outside (> 50) its stated region the typical epoch was
  double median_percentile = kNaN;
  nlohmann::json to_json() const;
};

/// Per-axis 1-sigma (m) of a reference fix: its stated accuracy (the 68 % radius,
/// FixSample::kAccuracyRadiusPerSigma), or default_accuracy_m when it states none.
double fix_sigma_m(const FixSample& f, double default_accuracy_m = 15.0);

/// A Fix row that is a reference position (replay's error figures, eval-outage, eval-pdr
/// --reference fixes): provider GPS (any case; network and fused fixes are not), finite
/// latitude and longitude.
bool is_gps_reference_fix(const FixSample& f);

/// One output epoch of the replay.
struct Epoch {
  Estimate est;
  bool has_ref = false;
  geo::Geodetic ref;
  double err_e_m = 0.0, err_n_m = 0.0;
  double mahalanobis2 = 0.0;  // err' P^-1 err
  bool inside_1sigma = false;
};

/// Collects reference positions and estimates during a replay.
class ReplayRecorder {
 public:
  void observe_reference(const Sample& s);
  void observe_estimate(const Estimate& e);
  /// Attach references to epochs (interpolated truth, or the nearest GPS fix within 1 s).
  void finish();
  const std::vector<Epoch>& epochs() const { return epochs_; }
  std::map<std::string, std::int64_t> epochs_by_engine() const;
  ErrorStats error_stats() const;
  std::string reference_kind() const;
  void write_track_csv(const std::string& path) const;
  /// Every running engine's own estimate (NavigatorOutput::engines), kept at most once per
  /// kEngineIntervalS of log time: which engine said what when the fused estimate moved.
  void observe_engines(TimeNs t_ns, const std::vector<Estimate>& engines);
  bool engines_due(TimeNs t_ns) const { return last_engines_t_ < 0 || t_ns >= last_engines_t_ + s_to_ns(kEngineIntervalS); }
  static constexpr double kEngineIntervalS = 1.0;
  /// engines.csv: t_ns, engine, status, position, covariance, semi-major, the reference and the
  /// error against it (as in the track CSV), reason.
  void write_engines_csv(const std::string& path) const;
  void write_geojson(const std::string& path, std::size_t max_ellipses = 400) const;
  /// Hand-overs of the fused estimate (time, "from -> to: reason"): the track CSV's last column
  /// (mode_change) carries each one on the first epoch at or after its time.
  void set_mode_changes(std::vector<std::pair<TimeNs, std::string>> changes);

 private:
  std::vector<std::pair<TimeNs, std::string>> mode_changes_;
  std::string mode_changes_up_to(TimeNs t_ns, std::size_t* next) const;
  struct Ref { TimeNs t_ns; geo::Geodetic p; };
  bool reference_at(TimeNs t, geo::Geodetic* out) const;
  std::vector<Ref> truth_;
  std::vector<Ref> fixes_;
  std::vector<Epoch> epochs_;
  std::vector<Estimate> engine_rows_;
  TimeNs last_engines_t_ = -1;
  TimeNs last_t_ = -1;
  EstimateStatus last_status_ = EstimateStatus::kNotInitialized;
};

/// The PDR part of replay's summary.json: steps (the Navigator's count), distance walked (sum
/// of step lengths), placement bouts with their time spans (s from the first sample) and
/// walking direction in phone axes, steps refused by the motion classifier.
nlohmann::json pdr_summary_json(const pdr::Pdr& pdr, std::int64_t navigator_steps, TimeNs t0_ns);
/// What `replay` and `inspect` say of an accelerometer slower than pdr::Pdr::kMinAccelRateHz.
std::string accel_rate_warning(double rate_hz);

/// A PDR calibration (fusion::PdrCalibrator) in summary.json / eval-outage JSON: scale and
/// heading bias with their sigmas, the window's epochs and baseline, the residual correlation
/// and the course-over-ground samples that went into the heading.
nlohmann::json pdr_calibration_json(const fusion::PdrCalibration& c);

/// Ellipse outline (lon, lat) polygon for an estimate at probability scale k (1 = 1-sigma).
std::vector<std::pair<double, double>> ellipse_polygon(const Estimate& e, double k, int points = 36);

}  // namespace pdnav::cli
