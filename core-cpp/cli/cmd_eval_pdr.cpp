// pdnav eval-pdr LOG...: PDR trajectories on real walks with surveyed waypoints (issue 16).
// Each log (e.g. an ILC walk converted by tools/ilc2log) is replayed; the track starts at the
// first Truth line (waypoint) at its time and is scored at every later one. Per walk: the
// waypoint errors, the heading error of every segment (estimated displacement vs surveyed
// segment, + = clockwise), the length ratio (estimated path / waypoint polyline), and the same
// for a naive PDR (peaks of low-passed |a|, 0.70 m steps, rotation-vector yaw of +Y).
// Beside them, "still": the walker never leaves the start. Logs with dense truth (motion
// capture, tools/tyrex2log) use --segment-min-m (a segment ends once the truth has moved that
// far along its path) and --align-start-s (the track rotated about the start to fit the truth
// over the first seconds: relative heading, the RMS % of distance). --sensors keeps
// one sensor set of the log (accel, imu, rv, uncal, game, accelmag, all); --speed, --rate, --turn,
// --pitch and --wave replay the walk as another phone, grip or start would give it; --json writes one object per
// walk (Meta Carry/Gait/Disturbance/TruthSteps included) for tools/eval-pdr-all.
// Last line: `median_mean_error_m: X median_length_ratio: Y`.
//   --via navigator (default): fusion::Navigator in dead-reckoning mode, exactly what
//                              `pdnav replay --engine dr` runs;
//   --via pdr: pdr::Pdr integrated step by step, with --length/--k to compare length models.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <iomanip>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "pdnav/fusion/navigator.h"
#include "pdnav/geo/frames.h"
#include "pdnav/geo/wmm.h"
#include "pdnav/io/log_reader.h"
#include "pdnav/io/log_writer.h"
#include "pdnav/io/sample_source.h"
#include "pdnav/pdr/pdr.h"
#include "pdnav/phonesim/handling.h"
#include "pdnav/phonesim/sample_rate.h"
#include "pdnav/phonesim/walk_speed.h"
#include "support/eval_support.h"
#include "support/output_file.h"
#include "support/replay_support.h"

namespace pdnav::cli {
namespace {

struct EvalPdrArgs {
  std::vector<std::string> logs;
  std::string mount = "auto";
  std::string via = "navigator";
  std::string length = "default";
  double k = kNaN;
  double height_m = kNaN;
  bool quiet = false;
  bool legacy = false;
  bool no_declination = false;  // diagnostic (--via pdr): magnetic headings, no WMM tests
  double tau_s = kNaN;          // heading fusion offset memory (with --via pdr)
  double field_tolerance = kNaN;
  double disturbed_weight = kNaN;
  double non_qsf_weight = kNaN;  // quasi-static field detector (with --via pdr)
  double qsf_std_deg = kNaN;
  double qsf_field_std_ut = kNaN;
  double qsf_window_s = kNaN;
  bool compass_only = false;  // diagnostic (--via pdr): no rotation vector, heading from the raw compass
  double wave_s = 0.0;        // seconds of synthesised calibration waving at the start point (0 = none)
  std::uint64_t wave_seed = 1;
  double wave_amplitude = 1.0;
  double pitch_deg = 0.0;     // every walk with the phone pitched this much further (0 = as recorded)
  double rate_hz = 0.0;       // motion sensors block-averaged to at most this rate (0 = as recorded)
  double speed = 1.0;         // the walk this many times faster along the same path (1 = as recorded)
  double turn_deg = 0.0;      // every walk with the phone turned this much in the hand about its Z axis
  std::vector<double> hard_iron_ut;  // every walk's magnetometer with this hard iron left in it (empty = as recorded)
  std::string sensors = "all";  // sensor set kept from each log (sensor_set_keeps)
  double segment_min_m = 0.0;   // 0: a segment per Truth line (surveyed waypoints)
  double align_start_s = 0.0;   // 0: no alignment (absolute tracks)
  std::string json_out;         // one JSON object per walk, one per line
  std::string write_logs_dir;   // each walk as evaluated (pitched, waved, sensor set) as a session log
  std::string reference = "auto";  // truth | fixes | auto (Truth lines when a log has 2+, else its fixes)
  double fix_max_accuracy_m = 10.0;  // --reference fixes: fixes stating a worse 68 % accuracy are not scored
};

/// Whether a sample belongs to the sensor set (issue 27 "every sensor set"): accel =
/// accelerometer only (Oxford); imu = accelerometer, gyroscope, magnetometer; rv = the
/// rotation vector only (what `pdnav simulate` writes, with its step events); uncal = the
/// uncalibrated streams (UncalAccel/UncalGyro/UncalMag, the calibrated accelerometer where no
/// UncalAccel is logged); game = accelerometer, gyroscope, game rotation vector; accelmag =
/// accelerometer and magnetometer (a phone without a gyroscope); all = as recorded. Truth, Meta
/// and step events always pass (the step events are the phone's).
bool sensor_set_keeps(const std::string& set, const Sample& s) {
  if (set == "all" || std::holds_alternative<TruthSample>(s) || std::holds_alternative<MetaSample>(s)) return true;
  const bool acc = std::holds_alternative<AccelSample>(s), gyro = std::holds_alternative<GyroSample>(s),
             mag = std::holds_alternative<MagSample>(s), rv = std::holds_alternative<RotationVectorSample>(s),
             steps = std::holds_alternative<StepDetectorSample>(s) || std::holds_alternative<StepCounterSample>(s),
             uncal = std::holds_alternative<UncalAccelSample>(s) || std::holds_alternative<UncalGyroSample>(s) ||
                     std::holds_alternative<UncalMagSample>(s),
             game = std::holds_alternative<GameRotationVectorSample>(s);
  if (set == "accel") return acc;
  if (set == "imu") return acc || gyro || mag;
  if (set == "rv") return rv || steps;
  if (set == "uncal") return uncal || acc;
  if (set == "game") return acc || gyro || game;
  if (set == "accelmag") return acc || mag;
  throw std::invalid_argument("--sensors: expected all, accel, imu, rv, uncal, game or accelmag");
}

/// The naive reference PDR of the issue: low-passed |a| peaks, fixed 0.70 m, RV yaw.
class NaivePdr {
 public:
  void feed(const AccelSample& s) {
    const double m = s.acc_mps2.norm();
    if (!std::isfinite(m)) return;
    const double dt = have_ ? ns_to_s(s.t_ns - last_ns_) : 0.0;
    if (!have_ || dt <= 0.0 || dt > 0.5) {
      lp_ = m, prev_ = m, prev2_ = m;
    } else {
      const double a = dt / (1.0 / (2.0 * kPi * kCutHz) + dt);
      prev2_ = prev_;
      prev_ = lp_;
      lp_ += a * (m - lp_);
      // a local maximum above the threshold, at least kMinGap after the last step
      if (prev_ > prev2_ && prev_ >= lp_ && prev_ > kStandardGravity_mps2 + kPeakAboveG &&
          ns_to_s(s.t_ns - last_step_ns_) > kMinGapS && have_yaw_) {
        pos_en_ += kStepM * Eigen::Vector2d(std::sin(yaw_rad_), std::cos(yaw_rad_));
        last_step_ns_ = s.t_ns;
        ++steps_;
        step_times_.push_back(s.t_ns);
      }
    }
    have_ = true;
    last_ns_ = s.t_ns;
  }
  void feed(const RotationVectorSample& s, double declination_rad) {
    const auto h = pdr::rotation_vector_heading_rad(s.quat_xyzw, Eigen::Vector3d::UnitY(), 0.25);
    if (h) yaw_rad_ = *h + declination_rad, have_yaw_ = true;
  }
  void start(const Eigen::Vector2d& en) { pos_en_ = en, steps_at_start_ = steps_; }
  std::int64_t steps_since_start() const { return steps_ - steps_at_start_; }
  const Eigen::Vector2d& pos_en() const { return pos_en_; }
  std::int64_t steps() const { return steps_; }
  /// false when the log has no rotation vector: this baseline is then not defined (n/a)
  bool has_yaw() const { return have_yaw_; }
  const std::vector<TimeNs>& step_times() const { return step_times_; }

 private:
  std::int64_t steps_ = 0, steps_at_start_ = 0;
  std::vector<TimeNs> step_times_;
  static constexpr double kCutHz = 3.0, kPeakAboveG = 1.0, kMinGapS = 0.3, kStepM = 0.70;
  bool have_ = false, have_yaw_ = false;
  TimeNs last_ns_ = 0, last_step_ns_ = 0;
  double lp_ = 0, prev_ = 0, prev2_ = 0, yaw_rad_ = 0;
  Eigen::Vector2d pos_en_ = Eigen::Vector2d::Zero();
};

struct WalkResult {
  std::string name;
  std::vector<double> errors_m, naive_errors_m, seg_heading_err_deg, naive_seg_heading_err_deg;
  // per segment: the RMS of the stated heading 1-sigma of the steps in it (NaN: no step)
  std::vector<double> seg_heading_sigma_deg;
  // per segment: its middle, s after the walk's first Truth line (the heading error as a time series)
  std::vector<double> seg_mid_s;
  double mean_m = kNaN, naive_mean_m = kNaN, length_ratio = kNaN, naive_ratio = kNaN;
  std::int64_t steps = 0;
  double declination_deg = kNaN;
  std::int64_t qsf_tested = 0, qsf_static = 0;  // --via pdr: magnetometer readings, quasi-static ones
  std::int64_t waving_steps = -1, naive_waving_steps = -1;  // --wave: steps out before the walk began
  std::map<std::string, std::string> meta;  // the log's Meta lines (latest value per key)
  std::vector<double> still_errors_m;       // "still": the estimate stays at the start
  std::int64_t naive_steps = 0;
  std::string reference = "truth";        // what the walk was scored against (truth | fixes)
  std::int64_t fixes_used = 0, fixes_rejected = 0;  // --reference fixes: scored / not (accuracy, provider)
  std::int64_t steps_in_truth_span = -1, naive_steps_in_truth_span = -1;  // -1: no Meta TruthStepsFrom/ToNanos
  double truth_path_m = kNaN, final_m = kNaN, naive_final_m = kNaN, still_final_m = kNaN;
  double rms_pct = kNaN, naive_rms_pct = kNaN, still_rms_pct = kNaN;  // RMS error / truth path, % (aligned)
  double align_deg = kNaN, naive_align_deg = kNaN;  // --align-start-s: rotation applied to the track
  std::int64_t samples_dropped_by_sensor_set = 0;
  // the estimate's stated covariance against its error (+ the reference's own, for fixes):
  // scored points with a covariance, inside the 68 % region (kOneSigmaM2), inside 1 sigma (d^2 <= 1)
  std::int64_t cov_scored = 0, cov_inside_68 = 0, cov_inside_1sigma = 0;
  std::vector<double> cov_m2;  // ... and each one's squared Mahalanobis distance
  double median_percentile = kNaN;  // chi2_2dof_percent of their median (50 = calibrated)
  std::map<TimeNs, double> ref_sigma_m;  // --reference fixes: per-axis 1-sigma of each fix
};

/// Linear-interpolated percentile (0-100) of the finite values.
double percentile(std::vector<double> v, double pct) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  if (v.empty()) return kNaN;
  std::sort(v.begin(), v.end());
  const double pos = pct / 100.0 * static_cast<double>(v.size() - 1);
  const std::size_t lo = static_cast<std::size_t>(pos);
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

double mean(const std::vector<double>& v) {
  if (v.empty()) return kNaN;
  double s = 0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

pdr::PdrOptions pdr_options_for(const EvalPdrArgs& a) {
  pdr::PdrOptions o;
  o.heading.mount = pdr::mount_from_string(a.mount);
  o.source = pdr::StepSource::kAuto;
  o.length = std::isfinite(a.height_m) ? pdr::StepLengthModel::apt_male(a.height_m)
                                       : pdr::StepLengthModel::unknown_walker();  // as the Navigator
  if (a.length == "apt") o.length = pdr::StepLengthModel::apt_male(std::isfinite(a.height_m) ? a.height_m : 1.75);
  else if (a.length == "weinberg") o.length.kind = pdr::StepLengthKind::kWeinberg;
  else if (a.length == "frequency") o.length.kind = pdr::StepLengthKind::kFrequency;
  else if (a.length == "constant") o.length.kind = pdr::StepLengthKind::kConstant;
  else if (a.length != "default") throw std::invalid_argument("--length: expected default, apt, weinberg, frequency, constant");
  if (std::isfinite(a.tau_s)) o.fusion.tau_s = a.tau_s;
  if (std::isfinite(a.field_tolerance)) o.fusion.field_tolerance = a.field_tolerance;
  if (std::isfinite(a.disturbed_weight)) o.fusion.disturbed_weight = a.disturbed_weight;
  if (std::isfinite(a.non_qsf_weight)) o.fusion.non_qsf_weight = a.non_qsf_weight;
  if (std::isfinite(a.qsf_std_deg)) o.fusion.qsf_max_offset_std_rad = a.qsf_std_deg * kDegToRad;
  if (std::isfinite(a.qsf_field_std_ut)) o.fusion.qsf_max_field_std_ut = a.qsf_field_std_ut;
  if (std::isfinite(a.qsf_window_s)) o.fusion.qsf_window_s = a.qsf_window_s;
  if (a.legacy) {
    // the engine before issue 16: declared chest mount, heading = the latest rotation vector,
    // no magnetic gating, no motion gate, APT height model with 1.75 m
    o.heading.mount = pdr::Mount::kChestCameraOut;
    o.fusion.tau_s = 1e-3;
    o.fusion.field_tolerance = 1e9;
    o.fusion.dip_tolerance_rad = 1e9;
    o.gate_handling = false;
    o.length = pdr::StepLengthModel::apt_male(1.75);
  }
  if (std::isfinite(a.k)) {
    if (o.length.kind == pdr::StepLengthKind::kWeinberg) o.length.weinberg_k = a.k;
    else if (o.length.kind == pdr::StepLengthKind::kFrequency) o.length.frequency_scale = a.k;
    else if (o.length.kind == pdr::StepLengthKind::kConstant) o.length.constant_m = a.k;
    else o.length.c1 = a.k;
  }
  return o;
}

/// Position source: the Navigator (dr) or a directly integrated Pdr.
class Runner {
 public:
  explicit Runner(const EvalPdrArgs& a) : via_nav_(a.via == "navigator" && !a.legacy), wmm_(!a.no_declination) {
    if (a.no_declination && a.via == "navigator") throw std::invalid_argument("--no-declination needs --via pdr");
    if (a.via != "navigator" && a.via != "pdr") throw std::invalid_argument("--via: expected navigator or pdr");
    if (via_nav_) {
      fusion::NavigatorConfig c;
      c.mode = fusion::EngineMode::kDeadReckoning;
      c.mount = pdr::mount_from_string(a.mount);
      c.user_height_m = a.height_m;
      if (a.length != "default" || std::isfinite(a.k) || std::isfinite(a.tau_s) || std::isfinite(a.field_tolerance) ||
          std::isfinite(a.disturbed_weight))
        throw std::invalid_argument("--length/--k/--tau/--field-tolerance/--disturbed-weight need --via pdr");
      nav_ = std::make_unique<fusion::Navigator>(c, 1);
    } else {
      pdr_ = std::make_unique<pdr::Pdr>(pdr_options_for(a));
      compass_only_ = a.compass_only;
    }
  }
  void feed(const Sample& s) {
    if (nav_) {
      nav_->feed(s);
      for (const fusion::StepEstimate& st : nav_->take_steps()) {
        step_times_.push_back(st.estimate.t_ns);
        step_heading_sigma_rad_.push_back(st.heading_sigma_rad);
      }
      return;
    }
    std::visit(
        [&](const auto& x) {
          using T = std::decay_t<decltype(x)>;
          if constexpr (std::is_same_v<T, RotationVectorSample>) {
            if (!compass_only_) pdr_->feed(x);
          } else if constexpr (std::is_same_v<T, AccelSample> || std::is_same_v<T, GyroSample> ||
                               std::is_same_v<T, MagSample> || std::is_same_v<T, StepDetectorSample>) {
            pdr_->feed(x);
          }
        },
        s);
    for (const PdrStep& st : pdr_->take_steps()) {
      ++steps_;
      step_times_.push_back(st.t_ns);
      step_heading_sigma_rad_.push_back(st.heading_sigma_rad);
      if (started_) {
        const Eigen::Vector2d d = st.length_m * Eigen::Vector2d(std::sin(st.heading_rad), std::cos(st.heading_rad));
        en_ += d;
        path_m_ += d.norm();
      }
    }
  }
  /// sigma_m: the start point's own 1-sigma per axis (a surveyed point 1 m; a phone's fix its
  /// stated accuracy), so the stated covariance holds the start's error too.
  void start(const geo::Geodetic& g, TimeNs t_ns, const geo::LocalFrame& frame, double sigma_m) {
    frame_ = frame;
    started_ = true;
    en_ = frame.to_enu(g).p_m.head<2>();
    last_en_ = en_;
    path_m_ = 0;
    if (nav_) nav_->set_start(g.lat_deg(), g.lon_deg(), sigma_m, t_ns);
    if (pdr_ && wmm_) pdr_->set_location(g, kMissingInt);
  }
  void set_location(const geo::Geodetic& g, std::int64_t utc_ms) {
    if (pdr_ && wmm_) pdr_->set_location(g, utc_ms);
  }
  /// Current east/north in the evaluation frame; accumulates the path length of the navigator.
  std::optional<Eigen::Vector2d> position() {
    if (!started_) return std::nullopt;
    if (nav_) {
      const Estimate e = nav_->estimate();
      if (!e.valid()) return std::nullopt;
      cov_ = e.cov_en_m2;
      const Eigen::Vector2d p = frame_.to_enu(e.position).p_m.head<2>();
      path_m_ += (p - last_en_).norm();
      last_en_ = p;
      return p;
    }
    return en_;
  }
  double path_m() const { return path_m_; }
  /// The last estimate's stated covariance (the Navigator; a direct Pdr states none).
  std::optional<Eigen::Matrix2d> covariance() const { return cov_; }
  std::int64_t steps() const { return nav_ ? nav_->output(0).steps : steps_; }
  /// Each emitted step's own time (the dead-reckoning estimate's time after it).
  const std::vector<TimeNs>& step_times() const { return step_times_; }
  /// Each emitted step's stated heading 1-sigma (PdrStep::heading_sigma_rad), with step_times().
  const std::vector<double>& step_heading_sigma_rad() const { return step_heading_sigma_rad_; }
  /// Magnetometer readings tested for a quasi-static field and found so (direct Pdr only).
  std::pair<std::int64_t, std::int64_t> quasi_static_field() const {
    if (!pdr_) return {0, 0};
    const pdr::PdrCounters c = pdr_->counters();
    return {c.mag_readings_qsf_tested, c.mag_readings_quasi_static};
  }

 private:
  bool via_nav_;
  bool wmm_;
  std::unique_ptr<fusion::Navigator> nav_;
  bool compass_only_ = false;
  std::unique_ptr<pdr::Pdr> pdr_;
  geo::LocalFrame frame_;
  bool started_ = false;
  Eigen::Vector2d en_ = Eigen::Vector2d::Zero(), last_en_ = Eigen::Vector2d::Zero();
  double path_m_ = 0;
  std::int64_t steps_ = 0;
  std::vector<TimeNs> step_times_;
  std::vector<double> step_heading_sigma_rad_;
  std::optional<Eigen::Matrix2d> cov_;
};

/// Heading error of an estimated displacement against the surveyed segment, degrees, + =
/// clockwise; NaN when either is too short to have a direction.
double segment_heading_error_deg(const Eigen::Vector2d& truth_en, const Eigen::Vector2d& est_en) {
  if (truth_en.norm() <= 1.0 || est_en.norm() <= 0.5) return kNaN;
  return wrap_pi(std::atan2(est_en.x(), est_en.y()) - std::atan2(truth_en.x(), truth_en.y())) / kDegToRad;
}

std::vector<Sample> read_samples(const std::string& path) {
  const std::unique_ptr<io::SampleSource> source = io::open_sample_source(path);  // any format
  io::SampleSource& reader = *source;
  std::vector<Sample> out;
  Sample s;
  while (reader.next(s)) out.push_back(s);
  return out;
}

std::vector<Sample> rotated_phone(const std::vector<Sample>& in, const Eigen::AngleAxisd& rot);

/// "x,y,z" in uT, each finite and within +-1000 (a phone's hard iron is tens of uT); throws
/// CLI::ValidationError naming what was given.
std::vector<double> parse_hard_iron(const std::string& text) {
  const auto v = parse_number_list(text);
  if (!v || v->size() != 3 || std::any_of(v->begin(), v->end(), [](double x) { return std::abs(x) > 1000.0; }))
    throw CLI::ValidationError("expected x,y,z in uT (three numbers within +-1000), got '" + text + "'");
  return *v;
}

/// The walk with a hard iron the phone did not calibrate out (--hard-iron, phone axes, uT): added to
/// every magnetometer reading, calibrated or not (an uncalibrated reading's stated bias does not
/// know it), as a phone whose calibration has not converged (Android accuracy 0-1) or a raw iOS
/// magnetometer records it. The rotation vectors and orientation angles the phone computed from
/// its own field would carry it too and cannot be recomputed here: they are dropped (the naive
/// PDR, which reads them, then has no heading); the game rotation vector uses no magnetometer.
std::vector<Sample> with_hard_iron(const std::vector<Sample>& in, const std::vector<double>& b) {
  const Eigen::Vector3d bias(b.at(0), b.at(1), b.at(2));
  std::vector<Sample> out;
  out.reserve(in.size());
  for (Sample s : in) {
    if (std::holds_alternative<RotationVectorSample>(s) || std::holds_alternative<OrientationSample>(s)) continue;
    if (auto* m = std::get_if<MagSample>(&s)) m->field_ut += bias;
    if (auto* m = std::get_if<UncalMagSample>(&s)) m->field_ut += bias;
    out.push_back(std::move(s));
  }
  return out;
}

/// The walk with the phone pitched --pitch degrees further, top edge up, about the walk's
/// horizontal lateral axis (+Y x the mean gravity, phone axes): the same physical walk with the
/// phone held at another pitch, the top edge's heading kept (a reader holds a phone at 28-65 deg,
/// issue 27).
std::vector<Sample> with_pitch(const std::vector<Sample>& in, double pitch_deg, const std::string& path) {
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  for (const Sample& s : in)
    if (const auto* x = std::get_if<AccelSample>(&s)) up += x->acc_mps2;
  const Eigen::Vector3d lateral = Eigen::Vector3d::UnitY().cross(up);
  if (!(up.norm() > 0.0) || lateral.norm() < 0.1 * up.norm())
    throw std::runtime_error(path + ": --pitch needs accelerometer samples and a phone whose +Y axis is not vertical on average");
  return rotated_phone(in, Eigen::AngleAxisd(pitch_deg * kDegToRad, lateral.normalized()));
}

/// The walk with the phone turned --turn degrees in the hand about its own Z axis (the screen's
/// normal; + = counter-clockwise seen from the screen): 90 holds a phone held for texting in
/// landscape, its walking direction along -X instead of +Y.
std::vector<Sample> with_turn(const std::vector<Sample>& in, double turn_deg) {
  return rotated_phone(in, Eigen::AngleAxisd(turn_deg * kDegToRad, Eigen::Vector3d::UnitZ()));
}

/// Every phone-axes stream of the walk with the phone rotated by rot (the new phone axes in the
/// old ones): v' = R^T v for the accelerometer, gyroscope and magnetometer (and their
/// uncalibrated twins with their biases), q' = q R for the rotation vectors; the Android
/// orientation angles are dropped (they would be stale).
std::vector<Sample> rotated_phone(const std::vector<Sample>& in, const Eigen::AngleAxisd& rot) {
  const Eigen::Matrix3d rt = rot.toRotationMatrix().transpose();
  const Eigen::Quaterniond qr(rot);
  const auto turn_q = [&](Eigen::Vector4d& xyzw) {
    const Eigen::Quaterniond q = Eigen::Quaterniond(xyzw[3], xyzw[0], xyzw[1], xyzw[2]) * qr;
    xyzw = Eigen::Vector4d(q.x(), q.y(), q.z(), q.w());
  };
  std::vector<Sample> out;
  out.reserve(in.size());
  for (Sample s : in) {
    if (std::holds_alternative<OrientationSample>(s)) continue;
    std::visit(
        [&](auto& x) {
          using T = std::decay_t<decltype(x)>;
          if constexpr (std::is_same_v<T, AccelSample>) x.acc_mps2 = rt * x.acc_mps2;
          else if constexpr (std::is_same_v<T, GyroSample>) x.rate_radps = rt * x.rate_radps;
          else if constexpr (std::is_same_v<T, MagSample>) x.field_ut = rt * x.field_ut;
          else if constexpr (std::is_same_v<T, UncalAccelSample>) x.acc_mps2 = rt * x.acc_mps2, x.bias_mps2 = rt * x.bias_mps2;
          else if constexpr (std::is_same_v<T, UncalGyroSample>) x.rate_radps = rt * x.rate_radps, x.drift_radps = rt * x.drift_radps;
          else if constexpr (std::is_same_v<T, UncalMagSample>) x.field_ut = rt * x.field_ut, x.bias_ut = rt * x.bias_ut;
          else if constexpr (std::is_same_v<T, RotationVectorSample> || std::is_same_v<T, GameRotationVectorSample>) turn_q(x.quat_xyzw);
        },
        s);
    out.push_back(std::move(s));
  }
  return out;
}

/// The walk as if the walker had first waved the phone for --wave seconds standing at the first
/// waypoint (the "as recorded" sessions, which start with calibration waving): the first
/// Truth line moves to the start of the waving, the synthesised samples (phonesim/handling.h)
/// end 20 ms before the first sensor sample, in its attitude and field, with uncalibrated twins
/// where the walk logs them (its first bias of each). walk_start_ns: the original first waypoint time.
std::vector<Sample> with_waving(const std::vector<Sample>& in, const EvalPdrArgs& a, const std::string& path,
                                TimeNs* walk_start_ns) {
  phonesim::WavingEnd end;
  std::optional<std::size_t> truth0, first_sensor;
  std::vector<Eigen::Vector3d> acc, rate;
  // a phone that logs the uncalibrated streams logs them while waved too: their twins, with the
  // walk's first bias of each
  std::optional<Eigen::Vector3d> accel_bias, gyro_drift, mag_bias;
  std::int64_t utc_minus_ns_ms = kMissingInt;  // utc_ms - t_ns / 1e6 of the first accelerometer sample
  for (std::size_t i = 0; i < in.size(); ++i) {
    const Sample& s = in[i];
    if (std::holds_alternative<TruthSample>(s) && !truth0) truth0 = i;
    if (const auto* x = std::get_if<AccelSample>(&s)) {
      if (!first_sensor) first_sensor = i, end.accel_phone_mps2 = x->acc_mps2;
      if (x->utc_ms != kMissingInt && utc_minus_ns_ms == kMissingInt) utc_minus_ns_ms = x->utc_ms - x->t_ns / 1'000'000;
      if (acc.size() < 110) acc.push_back(x->acc_mps2);
    } else if (const auto* x = std::get_if<GyroSample>(&s)) {
      if (rate.size() < 110) rate.push_back(x->rate_radps);
    } else if (const auto* x = std::get_if<RotationVectorSample>(&s)) {
      if (!end.rotation_xyzw) end.rotation_xyzw = x->quat_xyzw;
    } else if (const auto* x = std::get_if<MagSample>(&s)) {
      if (!end.field_phone_ut) end.field_phone_ut = x->field_ut;
    } else if (const auto* x = std::get_if<UncalAccelSample>(&s)) {
      if (!accel_bias) accel_bias = x->bias_mps2;
    } else if (const auto* x = std::get_if<UncalGyroSample>(&s)) {
      if (!gyro_drift) gyro_drift = x->drift_radps;
    } else if (const auto* x = std::get_if<UncalMagSample>(&s)) {
      if (!mag_bias) mag_bias = x->bias_ut;
    }
  }
  if (!truth0 || !first_sensor) throw std::runtime_error(path + ": --wave needs a Truth line and accelerometer samples");
  end.t_end_ns = sample_time_ns(in[*first_sensor]) - 20'000'000;
  end.accel_noise_mps2 = phonesim::running_mean_residuals(acc);
  end.gyro_noise_radps = phonesim::running_mean_residuals(rate);
  phonesim::WavingOptions opt;
  opt.seconds = a.wave_s;
  opt.seed = a.wave_seed;
  opt.amplitude = a.wave_amplitude;
  const phonesim::WavingSamples w = phonesim::synthesize_waving(end, opt);
  *walk_start_ns = std::get<TruthSample>(in[*truth0]).t_ns;
  std::vector<Sample> out;
  const auto push_stamped = [&](auto x) {  // the walk's UTC clock, extended back over the waving
    x.utc_ms = utc_minus_ns_ms == kMissingInt ? kMissingInt : utc_minus_ns_ms + x.t_ns / 1'000'000;
    out.push_back(x);
  };
  for (std::size_t i = 0; i < *first_sensor; ++i)
    if (i != *truth0) out.push_back(in[i]);  // Meta lines
  TruthSample start = std::get<TruthSample>(in[*truth0]);
  start.t_ns = w.accel.empty() ? start.t_ns : std::min(start.t_ns, w.accel.front().t_ns);
  out.push_back(start);
  for (std::size_t k = 0; k < w.accel.size(); ++k) {  // per instant as the ILC logs: Accel, Mag, Gyro, RV
    const TimeNs t = w.accel[k].t_ns;
    push_stamped(w.accel[k]);
    if (accel_bias) push_stamped(UncalAccelSample{t, kMissingInt, w.accel[k].acc_mps2 + *accel_bias, *accel_bias});
    if (k < w.mag.size()) {
      push_stamped(w.mag[k]);
      if (mag_bias) push_stamped(UncalMagSample{w.mag[k].t_ns, kMissingInt, w.mag[k].field_ut + *mag_bias, *mag_bias});
    }
    push_stamped(w.gyro[k]);
    if (gyro_drift)
      push_stamped(UncalGyroSample{w.gyro[k].t_ns, kMissingInt, w.gyro[k].rate_radps + *gyro_drift, *gyro_drift});
    if (k < w.rotation.size()) push_stamped(w.rotation[k]);
  }
  for (std::size_t i = *first_sensor; i < in.size(); ++i)
    if (i != *truth0) out.push_back(in[i]);
  return out;
}

/// The phone's own fixes as the reference (a logger walk outdoors has no surveyed truth): each
/// GPS Fix row (is_gps_reference_fix, as replay and eval-outage) stating a 68 % accuracy <=
/// --fix-max-accuracy-m becomes a Truth point, the others are counted and dropped; Truth lines
/// already in the log are dropped (one reference per walk).
std::vector<Sample> fixes_as_reference(const std::vector<Sample>& in, double max_accuracy_m, WalkResult& r) {
  std::vector<Sample> out;
  out.reserve(in.size());
  for (const Sample& s : in) {
    if (std::holds_alternative<TruthSample>(s)) continue;
    const auto* f = std::get_if<FixSample>(&s);
    if (!f) {
      out.push_back(s);
      continue;
    }
    if (!is_gps_reference_fix(*f) || !std::isfinite(f->accuracy_m) || f->accuracy_m > max_accuracy_m) {
      ++r.fixes_rejected;
      continue;
    }
    TruthSample t;
    t.t_ns = f->t_ns;
    t.lat_deg = f->lat_deg;
    t.lon_deg = f->lon_deg;
    t.h_m = f->alt_m;
    out.push_back(t);
    r.ref_sigma_m[t.t_ns] = fix_sigma_m(*f);
    ++r.fixes_used;
  }
  return out;
}

/// The --write-logs file of each input: its file name (+ .log) in the folder, "-2", "-3", ...
/// before the extension when two inputs share a name; an input the name would overwrite is an
/// error (a recorded session is never written over).
std::vector<std::string> written_log_paths(const EvalPdrArgs& a) {
  std::vector<std::string> out;
  if (a.write_logs_dir.empty()) return out;
  std::set<std::string> used;
  for (const std::string& log : a.logs) {
    std::string base = std::filesystem::path(log).filename().string();  // a file, a folder or a zip
    if (base.empty()) base = std::filesystem::path(log).parent_path().filename().string();  // "dir/"
    if (base.size() >= 4 && base.compare(base.size() - 4, 4, ".log") == 0) base.resize(base.size() - 4);
    std::string name = base + ".log";
    for (int k = 2; used.count(name); ++k) name = base + "-" + std::to_string(k) + ".log";
    if (name != base + ".log") std::cerr << "eval-pdr: " << log << " is written as " << name << " (another input has its name)\n";
    used.insert(name);
    const std::string target = (std::filesystem::path(a.write_logs_dir) / name).string();
    refuse_writing_over_input(target, a.logs, "--write-logs: ", "write the evaluated walks to another folder");
    out.push_back(target);
  }
  return out;
}

/// RMS of the stated heading 1-sigma of the steps emitted in (from_ns, to_ns], degrees (NaN: no
/// step with a finite sigma there): what a heading segment's error is judged against.
double rms_step_sigma_deg(const Runner& run, TimeNs from_ns, TimeNs to_ns) {
  const std::vector<TimeNs>& t = run.step_times();
  const std::vector<double>& sigma = run.step_heading_sigma_rad();
  double sq = 0;
  int n = 0;
  for (std::size_t k = 0; k < t.size() && k < sigma.size(); ++k)  // emission order: no sortedness assumed
    if (t[k] > from_ns && t[k] <= to_ns && std::isfinite(sigma[k]) && sigma[k] > 0.0) sq += sigma[k] * sigma[k], ++n;
  return n > 0 ? std::sqrt(sq / n) / kDegToRad : kNaN;
}

/// Segments whose heading error is within the stated 1-sigma of their steps, and segments with
/// both (an honest Gaussian sigma holds 68 % of them).
std::pair<std::int64_t, std::int64_t> heading_within_sigma(const WalkResult& r) {
  std::int64_t within = 0, stated = 0;
  for (std::size_t k = 0; k < r.seg_heading_err_deg.size() && k < r.seg_heading_sigma_deg.size(); ++k) {
    const double e = r.seg_heading_err_deg[k], s = r.seg_heading_sigma_deg[k];
    if (!std::isfinite(e) || !std::isfinite(s)) continue;
    ++stated;
    within += std::abs(e) <= s;
  }
  return {within, stated};
}

WalkResult eval_walk(const std::string& path, const EvalPdrArgs& a, const std::string& write_path) {
  WalkResult r;
  r.name = path.substr(path.find_last_of('/') == std::string::npos ? 0 : path.find_last_of('/') + 1);
  std::vector<Sample> samples = read_samples(path);
  const auto truth_lines = std::count_if(samples.begin(), samples.end(),
                                         [](const Sample& s) { return std::holds_alternative<TruthSample>(s); });
  if (a.reference == "fixes" || (a.reference == "auto" && truth_lines < 2)) {
    samples = fixes_as_reference(samples, a.fix_max_accuracy_m, r);
    r.reference = "fixes";
    if (r.fixes_used < 2) {
      std::ostringstream o;
      o << path << ": fewer than 2 Truth lines and fewer than 2 fixes stating accuracy <= " << a.fix_max_accuracy_m
        << " m (" << r.fixes_used << " such fixes, " << r.fixes_rejected << " other fixes: worse, without accuracy or not GPS): nothing to score";
      throw std::runtime_error(o.str());
    }
  }
  TimeNs walk_start_ns = std::numeric_limits<TimeNs>::min();
  if (a.speed != 1.0) samples = phonesim::at_walk_speed(samples, a.speed);
  if (a.rate_hz > 0.0) samples = phonesim::at_sample_rate(samples, a.rate_hz);
  if (a.turn_deg != 0.0) samples = with_turn(samples, a.turn_deg);
  if (a.pitch_deg != 0.0) samples = with_pitch(samples, a.pitch_deg, path);
  if (a.wave_s > 0.0) samples = with_waving(samples, a, path, &walk_start_ns);
  if (!a.hard_iron_ut.empty()) samples = with_hard_iron(samples, a.hard_iron_ut);
  if (!write_path.empty()) {  // what is scored below, replayable with `pdnav replay`
    OutputFile out(write_path, a.logs);
    io::LogWriter w(out.partial_path());
    // The scoring below starts the dead reckoning at the first Truth point; a log that does not
    // state that start itself (the phone's fixes as the reference: its Fix rows become Truth)
    // gets it as Meta rows, so `pdnav replay` of the written log starts there too.
    const bool states_start = std::any_of(samples.begin(), samples.end(), [](const Sample& s) {
      const auto* m = std::get_if<MetaSample>(&s);
      return m && m->key == "StartLatitudeDegrees";
    });
    bool start_written = states_start;
    for (const Sample& s : samples) {
      if (!sensor_set_keeps(a.sensors, s)) continue;
      if (const auto* t = std::get_if<TruthSample>(&s);
          !start_written && t && std::isfinite(t->lat_deg) && std::isfinite(t->lon_deg)) {
        const auto sigma = r.ref_sigma_m.find(t->t_ns);
        const double sigma_m = sigma != r.ref_sigma_m.end() ? std::max(1.0, sigma->second) : 1.0;
        const auto text = [](double v) {
          std::ostringstream os;
          os << std::setprecision(12) << v;
          return os.str();
        };
        w.write(MetaSample{t->t_ns, "StartLatitudeDegrees", text(t->lat_deg)});
        w.write(MetaSample{t->t_ns, "StartLongitudeDegrees", text(t->lon_deg)});
        w.write(MetaSample{t->t_ns, "StartSigmaMeters", text(sigma_m)});
        start_written = true;
      }
      w.write(s);
    }
    w.close();
    out.commit();
  }
  Runner run(a);
  NaivePdr naive;
  geo::LocalFrame frame;
  bool started = false;
  const double declination = 0.0;  // naive: magnetic heading (see below)
  std::int64_t first_utc = kMissingInt;
  std::vector<Eigen::Vector2d> truth_en, est_en, naive_en;
  std::vector<TimeNs> truth_t;
  std::size_t seg_start = 0;  // index of the current heading segment's first Truth point
  double seg_path_m = 0;      // truth path since it
  double naive_path_m = 0;
  Eigen::Vector2d naive_last = Eigen::Vector2d::Zero();
  for (const Sample& s : samples) {
    if (!sensor_set_keeps(a.sensors, s)) {
      ++r.samples_dropped_by_sensor_set;
      continue;
    }
    if (const auto* m = std::get_if<MetaSample>(&s)) r.meta[m->key] = m->value;
    if (a.wave_s > 0.0 && r.waving_steps < 0 && sample_time_ns(s) >= walk_start_ns && !std::holds_alternative<MetaSample>(s)) {
      r.waving_steps = run.steps();
      r.naive_waving_steps = naive.steps();
    }
    if (const auto* m = std::get_if<AccelSample>(&s); m && first_utc == kMissingInt && m->utc_ms != kMissingInt)
      first_utc = m->utc_ms;
    if (const auto* t = std::get_if<TruthSample>(&s)) {
      const geo::Geodetic g = geo::Geodetic::from_deg(t->lat_deg, t->lon_deg, 0.0);
      if (!std::isfinite(t->lat_deg) || !std::isfinite(t->lon_deg)) continue;
      if (!started) {
        frame = geo::LocalFrame(g);
        const auto start_sigma = r.ref_sigma_m.find(t->t_ns);  // the start fix's own error
        run.start(g, t->t_ns, frame, start_sigma != r.ref_sigma_m.end() ? std::max(1.0, start_sigma->second) : 1.0);
        naive.start(Eigen::Vector2d::Zero());
        started = true;
        // the naive PDR keeps the raw (magnetic) rotation-vector yaw, as the naive
        // reference does; ours gets the WMM declination like the Navigator
        if (first_utc != kMissingInt) run.set_location(g, first_utc);
        r.declination_deg = geo::magnetic_declination_rad(g, first_utc) / kDegToRad;
        truth_en.push_back(Eigen::Vector2d::Zero());
        est_en.push_back(Eigen::Vector2d::Zero());
        naive_en.push_back(naive.pos_en());
        truth_t.push_back(t->t_ns);
        continue;
      }
      const Eigen::Vector2d tr = frame.to_enu(g).p_m.head<2>();
      const auto p = run.position();
      const Eigen::Vector2d est = p ? *p : est_en.back();
      naive_path_m += (naive.pos_en() - naive_last).norm();
      naive_last = naive.pos_en();
      r.errors_m.push_back((est - tr).norm());
      if (const auto cov = run.covariance(); p && cov && cov->allFinite()) {
        Eigen::Matrix2d c = *cov;
        if (const auto it = r.ref_sigma_m.find(t->t_ns); it != r.ref_sigma_m.end())
          c += it->second * it->second * Eigen::Matrix2d::Identity();
        const double d2 = mahalanobis2(c, est - tr);
        ++r.cov_scored;
        r.cov_m2.push_back(d2);
        r.cov_inside_68 += d2 <= kOneSigmaM2;
        r.cov_inside_1sigma += d2 <= 1.0;
      }
      r.naive_errors_m.push_back((naive.pos_en() - tr).norm());
      r.still_errors_m.push_back(tr.norm());
      seg_path_m += (tr - truth_en.back()).norm();
      if (seg_path_m >= a.segment_min_m) {  // a segment ends here (every Truth line when 0)
        const Eigen::Vector2d dt = tr - truth_en[seg_start];
        r.seg_heading_err_deg.push_back(segment_heading_error_deg(dt, est - est_en[seg_start]));
        r.seg_heading_sigma_deg.push_back(rms_step_sigma_deg(run, truth_t[seg_start], t->t_ns));
        r.seg_mid_s.push_back(0.5 * ns_to_s(truth_t[seg_start] + t->t_ns - 2 * truth_t.front()));
        // the same for the naive PDR = the phone's own (magnetic) rotation-vector heading of +Y:
        // separates what the map frame and the field give from what our fusion adds
        r.naive_seg_heading_err_deg.push_back(segment_heading_error_deg(dt, naive.pos_en() - naive_en[seg_start]));
        seg_start = truth_en.size();
        seg_path_m = 0;
      }
      truth_en.push_back(tr);
      est_en.push_back(est);
      naive_en.push_back(naive.pos_en());
      truth_t.push_back(t->t_ns);
      continue;
    }
    run.feed(s);
    if (started) {
      run.position();  // accumulate the path
      std::visit(
          [&](const auto& x) {
            using T = std::decay_t<decltype(x)>;
            if constexpr (std::is_same_v<T, AccelSample>) {
              naive.feed(x);
              naive_path_m += (naive.pos_en() - naive_last).norm();
              naive_last = naive.pos_en();
            } else if constexpr (std::is_same_v<T, RotationVectorSample>) {
              naive.feed(x, declination);
            }
          },
          s);
    } else if (const auto* rv = std::get_if<RotationVectorSample>(&s)) {
      naive.feed(*rv, declination);
    }
  }
  if (truth_en.size() < 2) throw std::runtime_error(path + ": fewer than 2 Truth lines (waypoints): nothing to score");
  double truth_len = 0;
  for (std::size_t i = 1; i < truth_en.size(); ++i) truth_len += (truth_en[i] - truth_en[i - 1]).norm();
  r.mean_m = mean(r.errors_m);
  r.naive_mean_m = mean(r.naive_errors_m);
  r.length_ratio = truth_len > 0 ? run.path_m() / truth_len : kNaN;
  r.median_percentile = chi2_2dof_percent(median_mahalanobis2(r.cov_m2));
  r.naive_ratio = truth_len > 0 ? naive_path_m / truth_len : kNaN;
  r.steps = run.steps();
  r.naive_steps = naive.steps_since_start();
  // the span a step truth covers (tools/tyrex2log: the capture less half a window at each end)
  const auto span_meta = [&r, &path](const char* key) -> std::optional<TimeNs> {
    const auto it = r.meta.find(key);
    if (it == r.meta.end() || it->second.empty()) return std::nullopt;
    try {
      return static_cast<TimeNs>(std::stoll(it->second));
    } catch (const std::exception&) {
      throw std::runtime_error(path + ": Meta " + key + " is not an integer: " + it->second);
    }
  };
  const auto from = span_meta("TruthStepsFromNanos"), to = span_meta("TruthStepsToNanos");
  if (from && to) {
    const auto in_span = [&](const std::vector<TimeNs>& ts) {
      return static_cast<std::int64_t>(std::count_if(ts.begin(), ts.end(), [&](TimeNs t) { return t >= *from && t <= *to; }));
    };
    r.steps_in_truth_span = in_span(run.step_times());
    r.naive_steps_in_truth_span = in_span(naive.step_times());
  }
  std::tie(r.qsf_tested, r.qsf_static) = run.quasi_static_field();
  r.truth_path_m = truth_len;
  r.final_m = r.errors_m.back();
  r.naive_final_m = r.naive_errors_m.back();
  r.still_final_m = r.still_errors_m.back();
  // RMS error as % of the truth path, the tracks rotated about the start to fit the truth over
  // the first align_start_s (the metric for motion-capture walks; 0 = as estimated)
  const auto rms_pct = [&](const std::vector<Eigen::Vector2d>& est, double* align_deg) {
    double rot = 0.0;
    if (a.align_start_s > 0.0) {
      double cross = 0, dot = 0;
      for (std::size_t i = 1; i < est.size() && truth_t[i] - truth_t[0] <= s_to_ns(a.align_start_s); ++i) {
        cross += est[i].x() * truth_en[i].y() - est[i].y() * truth_en[i].x();
        dot += est[i].dot(truth_en[i]);
      }
      rot = (cross != 0.0 || dot != 0.0) ? std::atan2(cross, dot) : 0.0;  // counter-clockwise
    }
    *align_deg = -rot / kDegToRad;  // + = the track was turned clockwise
    const Eigen::Rotation2Dd R(rot);
    double sq = 0;
    for (std::size_t i = 1; i < est.size(); ++i) sq += (R * est[i] - truth_en[i]).squaredNorm();
    return truth_len > 0 ? 100.0 * std::sqrt(sq / static_cast<double>(est.size() - 1)) / truth_len : kNaN;
  };
  r.rms_pct = rms_pct(est_en, &r.align_deg);
  r.naive_rms_pct = rms_pct(naive_en, &r.naive_align_deg);
  if (!naive.has_yaw()) {  // no rotation vector in the log: the naive PDR has no heading, n/a
    r.naive_mean_m = r.naive_final_m = r.naive_ratio = r.naive_rms_pct = r.naive_align_deg = kNaN;
    r.naive_seg_heading_err_deg.clear();
    r.naive_steps = -1;  // its steps wait for a heading
  }
  double sq = 0;
  for (double e : r.still_errors_m) sq += e * e;
  r.still_rms_pct = truth_len > 0 ? 100.0 * std::sqrt(sq / static_cast<double>(r.still_errors_m.size())) / truth_len : kNaN;
  return r;
}

nlohmann::json walk_json(const WalkResult& r, const EvalPdrArgs& a) {
  const auto num = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
  std::vector<double> abs_h, naive_abs_h;
  for (double h : r.seg_heading_err_deg) abs_h.push_back(std::abs(h));
  for (double h : r.naive_seg_heading_err_deg) naive_abs_h.push_back(std::abs(h));
  nlohmann::json j;
  j["walk"] = r.name;
  j["meta"] = r.meta;
  j["sensors"] = a.sensors;
  j["reference"] = r.reference;
  if (r.reference == "fixes") {
    j["fixes_used"] = r.fixes_used;
    j["fixes_rejected"] = r.fixes_rejected;
    j["fix_max_accuracy_m"] = a.fix_max_accuracy_m;
  }
  j["samples_dropped_by_sensor_set"] = r.samples_dropped_by_sensor_set;
  j["scored_points"] = r.errors_m.size();
  j["truth_path_m"] = num(r.truth_path_m);
  j["steps"] = r.steps;
  j["naive_steps"] = r.naive_steps >= 0 ? nlohmann::json(r.naive_steps) : nlohmann::json(nullptr);
  if (r.steps_in_truth_span >= 0) {
    j["steps_in_truth_span"] = r.steps_in_truth_span;
    j["naive_steps_in_truth_span"] = r.naive_steps_in_truth_span;
  }
  j["mean_m"] = num(r.mean_m);
  j["final_m"] = num(r.final_m);
  j["naive_mean_m"] = num(r.naive_mean_m);
  j["naive_final_m"] = num(r.naive_final_m);
  j["still_mean_m"] = num(mean(r.still_errors_m));
  j["still_final_m"] = num(r.still_final_m);
  j["length_ratio"] = num(r.length_ratio);
  j["naive_length_ratio"] = num(r.naive_ratio);
  j["segments"] = r.seg_heading_err_deg.size();
  j["seg_heading_signed_median_deg"] = num(median_of_finite(r.seg_heading_err_deg));
  j["seg_heading_abs_median_deg"] = num(median_of_finite(abs_h));
  j["naive_seg_heading_signed_median_deg"] = num(median_of_finite(r.naive_seg_heading_err_deg));
  j["naive_seg_heading_abs_median_deg"] = num(median_of_finite(naive_abs_h));
  j["seg_heading_err_deg"] = r.seg_heading_err_deg;
  j["naive_seg_heading_err_deg"] = r.naive_seg_heading_err_deg;
  j["seg_heading_sigma_deg"] = r.seg_heading_sigma_deg;
  j["seg_mid_s"] = r.seg_mid_s;
  const auto [within, stated] = heading_within_sigma(r);
  j["seg_heading_stated"] = stated;
  j["seg_heading_within_sigma"] = stated > 0 ? num(static_cast<double>(within) / static_cast<double>(stated)) : nlohmann::json(nullptr);
  for (auto* k : {"seg_heading_err_deg", "naive_seg_heading_err_deg", "seg_heading_sigma_deg"})
    for (auto& x : j[k])
      if (!std::isfinite(x.get<double>())) x = nullptr;
  j["align_start_s"] = a.align_start_s;
  j["rms_pct"] = num(r.rms_pct);
  j["naive_rms_pct"] = num(r.naive_rms_pct);
  j["still_rms_pct"] = num(r.still_rms_pct);
  j["align_deg"] = num(r.align_deg);
  j["cov_scored"] = r.cov_scored;
  j["coverage_68"] = r.cov_scored > 0 ? num(static_cast<double>(r.cov_inside_68) / static_cast<double>(r.cov_scored)) : nlohmann::json(nullptr);
  j["coverage_1sigma"] = r.cov_scored > 0 ? num(static_cast<double>(r.cov_inside_1sigma) / static_cast<double>(r.cov_scored)) : nlohmann::json(nullptr);
  // where the walk's median error falls in its stated distribution (50 = calibrated): a walk's
  // error is correlated along it, so its coverage is a few draws
  j["median_percentile"] = num(r.median_percentile);
  j["naive_align_deg"] = num(r.naive_align_deg);
  return j;
}

std::string join(const std::vector<double>& v, int prec) {
  std::ostringstream o;
  o << std::fixed << std::setprecision(prec);
  for (std::size_t i = 0; i < v.size(); ++i) o << (i ? " " : "") << v[i];
  return o.str();
}

int run_eval_pdr(const EvalPdrArgs& a) {
  (void)sensor_set_keeps(a.sensors, MetaSample{});  // reject a bad --sensors before any work
  std::vector<WalkResult> all;
  int failed = 0;
  std::ofstream json;
  if (!a.json_out.empty()) {
    json.open(a.json_out);
    if (!json) throw std::runtime_error("--json: cannot write " + a.json_out);
  }
  const std::vector<std::string> written = written_log_paths(a);
  std::size_t done = 0;
  for (const std::string& log : a.logs) {
    const std::string write_path = written.empty() ? std::string() : written[done];
    ++done;
    if (!a.json_out.empty()) std::cerr << "eval-pdr: [" << done << "/" << a.logs.size() << "] " << log << "\n";
    try {
      all.push_back(eval_walk(log, a, write_path));
    } catch (const std::exception& e) {
      std::cerr << "eval-pdr: " << e.what() << "\n";
      ++failed;
      continue;
    }
    if (json) json << walk_json(all.back(), a).dump() << "\n";
    const WalkResult& r = all.back();
    std::printf("%-48s wps %2zu steps %4lld mean_err_m %6.2f max %6.2f ratio %5.3f seg_heading_median %+5.1f | ",
                r.name.c_str(), r.errors_m.size() + 1, static_cast<long long>(r.steps), r.mean_m,
                *std::max_element(r.errors_m.begin(), r.errors_m.end()), r.length_ratio,
                median_of_finite(r.seg_heading_err_deg));
    if (std::isfinite(r.naive_mean_m)) std::printf("naive %6.2f ratio %5.3f\n", r.naive_mean_m, r.naive_ratio);
    else std::printf("naive n/a (no rotation vector: its heading)\n");
    if (r.reference == "fixes")
      std::printf("    reference: the phone's GPS fixes, %lld scored (accuracy <= %.1f m), %lld others not\n",
                  static_cast<long long>(r.fixes_used), a.fix_max_accuracy_m, static_cast<long long>(r.fixes_rejected));
    if (a.wave_s > 0.0)
      std::printf("    waving_steps: %lld (naive %lld)\n", static_cast<long long>(r.waving_steps),
                  static_cast<long long>(r.naive_waving_steps));
    if (!a.quiet) {
      std::printf("    waypoint_errors_m: %s\n", join(r.errors_m, 2).c_str());
      std::printf("    segment_heading_error_deg: %s\n", join(r.seg_heading_err_deg, 1).c_str());
    }
  }
  if (all.empty()) throw std::runtime_error("no walk could be evaluated");
  std::vector<double> means, ratios, naive_means, herr, naive_herr;
  int wins = 0;
  for (const auto& r : all) {
    means.push_back(r.mean_m);
    ratios.push_back(r.length_ratio);
    naive_means.push_back(r.naive_mean_m);
    wins += r.mean_m < r.naive_mean_m;
    for (double h : r.seg_heading_err_deg) herr.push_back(h);
    for (double h : r.naive_seg_heading_err_deg) naive_herr.push_back(h);
  }
  std::vector<double> abs_herr;
  for (double h : herr) abs_herr.push_back(std::abs(h));
  const bool any_naive = std::any_of(naive_means.begin(), naive_means.end(), [](double v) { return std::isfinite(v); });
  if (any_naive)
    std::printf("walks %zu (failed %d); better than naive in %d; naive median_mean_error_m %.2f\n", all.size(), failed, wins,
                median_of_finite(naive_means));
  else
    std::printf("walks %zu (failed %d); naive PDR n/a (no walk has a rotation vector)\n", all.size(), failed);
  std::printf("segment heading error: median signed %.1f deg, median |.| %.1f deg over %zu segments; WMM declination %.1f deg\n",
              median_of_finite(herr), median_of_finite(abs_herr), herr.size(), all.front().declination_deg);
  if (any_naive)
    std::printf("naive (rotation vector +Y, magnetic, no declination): segment heading error median signed %.1f deg\n",
                median_of_finite(naive_herr));
  std::int64_t h_within = 0, h_stated = 0;
  std::vector<double> h_sigma;
  for (const auto& r : all) {
    const auto [w, n] = heading_within_sigma(r);
    h_within += w, h_stated += n;
    for (double x : r.seg_heading_sigma_deg) h_sigma.push_back(x);
  }
  if (h_stated > 0)
    std::printf("heading segments whose error is within their steps' stated 1-sigma (median %.1f deg): %.3f of %lld "
                "(honest: 0.68)\n",
                median_of_finite(h_sigma), static_cast<double>(h_within) / static_cast<double>(h_stated), static_cast<long long>(h_stated));
  std::int64_t qsf_tested = 0, qsf_static = 0;
  for (const auto& r : all) qsf_tested += r.qsf_tested, qsf_static += r.qsf_static;
  if (qsf_tested > 0)
    std::printf("quasi-static field: %lld of %lld magnetometer readings (%.1f %%)\n", static_cast<long long>(qsf_static),
                static_cast<long long>(qsf_tested), 100.0 * static_cast<double>(qsf_static) / static_cast<double>(qsf_tested));
  if (a.wave_s > 0.0) {
    std::vector<double> ws, nws;
    int over = 0;
    for (const auto& r : all) {
      ws.push_back(static_cast<double>(r.waving_steps));
      nws.push_back(static_cast<double>(r.naive_waving_steps));
      over += r.waving_steps > 2;
    }
    std::printf("waving (%.0f s, seed %llu, amplitude %.2f): steps out before the walk: median %.0f, max %.0f, walks with > 2: %d of %zu (naive: median %.0f)\n",
                a.wave_s, static_cast<unsigned long long>(a.wave_seed), a.wave_amplitude, median_of_finite(ws),
                percentile(ws, 100), over, all.size(), median_of_finite(nws));
  }
  std::int64_t cs = 0, c68 = 0, c1 = 0;
  std::vector<double> walk_pct;
  for (const auto& r : all) {
    cs += r.cov_scored, c68 += r.cov_inside_68, c1 += r.cov_inside_1sigma;
    walk_pct.push_back(r.median_percentile);
  }
  if (cs > 0)
    std::printf("stated covariance (pooled over %lld scored points): inside the 68 %% region %.3f, inside 1 sigma %.3f (2-D Gaussian: 0.68, 0.39); "
                "median over the walks of the median error's percentile of its stated distribution %.1f (50 = calibrated)\n",
                static_cast<long long>(cs), static_cast<double>(c68) / static_cast<double>(cs),
                static_cast<double>(c1) / static_cast<double>(cs), median_of_finite(walk_pct));
  std::printf("per-walk mean error: p25 %.2f m, p75 %.2f m, max %.2f m\n", percentile(means, 25), percentile(means, 75),
              percentile(means, 100));
  std::printf("median_mean_error_m: %.2f median_length_ratio: %.3f\n", median_of_finite(means), median_of_finite(ratios));
  return failed ? 1 : 0;
}

}  // namespace

void register_eval_pdr(CLI::App& app) {
  auto a = std::make_shared<EvalPdrArgs>();
  CLI::App* c = app.add_subcommand("eval-pdr", "PDR on real walks with surveyed waypoints (Truth lines) or the phone's fixes: errors per walk");
  c->add_option("logs", a->logs,
                "session logs with Truth lines (tools/ilc2log converts the ILC walks) or the phone's fixes; any recording "
                "replay reads (Sensor Logger / phyphox folder or zip, GetSensorData log)")
      ->required()
      ->check(CLI::ExistingPath);
  c->add_option("--mount", a->mount, "auto | chest | chest-camera-out | chest-screen-out | hand")->capture_default_str();
  c->add_option("--via", a->via, "navigator (= replay --engine dr) | pdr (direct, for --length)")->capture_default_str();
  c->add_option("--length", a->length, "with --via pdr: default | apt | weinberg | frequency | constant")
      ->capture_default_str();
  c->add_option("--k", a->k, "with --via pdr: the length model's constant (c1, Weinberg K, frequency scale, metres)");
  c->add_option("--height", a->height_m, "walker height in metres (APT height model); default: unknown");
  c->add_option("--tau", a->tau_s, "with --via pdr: heading-fusion offset memory, s");
  c->add_option("--field-tolerance", a->field_tolerance, "with --via pdr: |B| tolerance vs WMM (fraction)");
  c->add_option("--disturbed-weight", a->disturbed_weight, "with --via pdr: weight of a disturbed reading");
  c->add_flag("--no-declination", a->no_declination,
              "diagnostic, with --via pdr: no WMM (magnetic headings, no field tests)");
  c->add_option("--non-qsf-weight", a->non_qsf_weight, "with --via pdr: weight of a reading outside a quasi-static field");
  c->add_option("--qsf-std", a->qsf_std_deg, "with --via pdr: QSF offset std threshold, deg");
  c->add_option("--qsf-field-std", a->qsf_field_std_ut, "with --via pdr: QSF |B| std threshold, uT");
  c->add_option("--qsf-window", a->qsf_window_s, "with --via pdr: QSF window, s");
  c->add_flag("--compass-only", a->compass_only, "with --via pdr: ignore the rotation vector (raw compass heading)");
  c->add_option("--wave", a->wave_s,
                 "seconds of synthesised compass-calibration waving at the first waypoint before the walk "
                 "(phonesim/handling.h; the track starts with it)")
      ->check(CLI::Range(0.0, 600.0));
  c->add_option("--wave-seed", a->wave_seed, "seed of the waving")->capture_default_str();
  c->add_option("--wave-amplitude", a->wave_amplitude, "scale of the waving's rotation and translation")
      ->check(CLI::Range(0.0, 3.0))
      ->capture_default_str();
  c->add_option("--rate", a->rate_hz,
                 "motion sensors as a phone sampling at most this rate would record them (Hz; each "
                 "accelerometer / gyroscope / magnetometer stream block-averaged, rotation vectors decimated)")
      ->check(CLI::Range(5.0, 1000.0));
  c->add_option("--speed", a->speed,
                 "every walk taken this many times faster along the same path (the cadence times it, the steps "
                 "as many): gravity kept, the gait's acceleration times its square, angular rates times it "
                 "(phonesim/walk_speed.h; before --rate)")
      ->check(CLI::Range(0.25, 4.0));
  c->add_option("--turn", a->turn_deg,
                 "every walk with the phone turned this much in the hand about its screen's normal (deg, + = "
                 "counter-clockwise seen from the screen; 90 = held in landscape): the same walk, another grip")
      ->check(CLI::Range(-180.0, 180.0));
  c->add_option("--hard-iron",
                 "every walk with this hard iron (x,y,z uT, phone axes) left in its magnetometer readings, as a "
                 "phone whose calibration has not converged records them: the same walk, another phone (its "
                 "rotation vectors, computed from that field, are dropped)")
      ->each([a](const std::string& text) { a->hard_iron_ut = parse_hard_iron(text); });
  c->add_option("--pitch", a->pitch_deg,
                 "every walk with the phone pitched this much further (deg, top edge up) about the walk's "
                 "horizontal lateral axis: the same walk, the phone held at another pitch")
      ->check(CLI::Range(-80.0, 80.0));
  c->add_option("--write-logs", a->write_logs_dir,
                 "write each walk as evaluated (pitched, waved, sensor set kept) as a session log in this "
                 "existing folder, under its input's file name (+ .log; -2, -3 ... for inputs of the same name; never over an "
                 "input), to replay or plot; with --reference fixes "
                 "the scored fixes are written as its Truth rows")
      ->check(CLI::ExistingDirectory);
  c->add_flag("--quiet", a->quiet, "one line per walk");
  c->add_option("--sensors", a->sensors, "sensor set kept from each log: all | accel | imu | rv | uncal | game | accelmag")
      ->capture_default_str();
  c->add_option("--segment-min-m", a->segment_min_m,
                "a heading segment ends once the truth moved this far along its path (0 = every Truth line)")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  c->add_option("--align-start-s", a->align_start_s,
                "rotate each track about the start to fit the truth over its first S seconds (RMS % metric; 0 = off)")
      ->check(CLI::Range(0.0, 3600.0))
      ->capture_default_str();
  c->add_option("--reference", a->reference,
                "truth (Truth lines) | fixes (the phone's Fix rows, e.g. a Sensor Logger walk outdoors) | auto "
                "(Truth when a log has 2 or more lines, else fixes)")
      ->check(CLI::IsMember({"truth", "fixes", "auto"}))
      ->capture_default_str();
  c->add_option("--fix-max-accuracy-m", a->fix_max_accuracy_m,
                "with fixes as the reference: score only fixes stating this 68 % accuracy or better")
      ->check(CLI::Range(0.5, 1000.0))
      ->capture_default_str();
  c->add_option("--json", a->json_out, "write one JSON object per walk (one per line) to this file");
  c->add_flag("--legacy", a->legacy,
              "the engine as before issue 16 (chest mount, latest rotation vector, APT 1.75 m, no motion gate)");
  c->callback([a]() {
    const int rc = run_eval_pdr(*a);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace pdnav::cli
