// Level-crossing step detector (APT, Zhu/Li/Chen 2013, Sec. V-A) with real-data gates.
#include "pdnav/pdr/step_detector.h"

#include <algorithm>
#include <cmath>
#include <complex>

#include "autocorrelation.h"
#include "lowpass.h"

namespace pdnav::pdr {

namespace {

/// Gain of the running average of the in-bout step interval (time constant ~8 steps).
constexpr double kIntervalGain = 0.125;

/// How much a 3-vector series (the phone's tilt, or its angular rate) swings at 1/I and at
/// 1/(2I) over the samples in [from, to]: single-bin DFTs of the series less its mean, as
/// amplitudes 2|X|/n.
struct SwingAmplitudes {
  double at_interval = 0.0, at_half = 0.0;
};
template <typename Samples, typename Value>
SwingAmplitudes swing_amplitudes(const Samples& samples, TimeNs from, TimeNs to, double interval_s, Value value) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  int n = 0;
  for (const auto& s : samples) {
    if (s.t_ns < from || s.t_ns > to) continue;
    mean += value(s);
    ++n;
  }
  if (n == 0) return {};
  mean /= n;
  Eigen::Vector3cd x1 = Eigen::Vector3cd::Zero(), xh = Eigen::Vector3cd::Zero();
  for (const auto& s : samples) {
    if (s.t_ns < from || s.t_ns > to) continue;
    const double ph = 2.0 * kPi * ns_to_s(s.t_ns - to) / interval_s;
    const Eigen::Vector3d d = value(s) - mean;
    x1 += d.cast<std::complex<double>>() * std::polar(1.0, -ph);
    xh += d.cast<std::complex<double>>() * std::polar(1.0, -0.5 * ph);
  }
  return {2.0 * x1.norm() / n, 2.0 * xh.norm() / n};
}

}  // namespace

SampleCheck check_sample(TimeNs t_ns, bool finite, TimeNs last_t_ns, bool have_last, double gap_reset_s,
                         SampleCounters& counters) {
  if (!finite) {
    ++counters.non_finite;
    return SampleCheck::kNonFinite;
  }
  if (have_last && t_ns == last_t_ns) {
    ++counters.duplicate_time;
    return SampleCheck::kDuplicate;
  }
  if (have_last && t_ns < last_t_ns) {
    ++counters.backwards_time;
    return SampleCheck::kBackwards;
  }
  ++counters.accepted;
  if (have_last && ns_to_s(t_ns - last_t_ns) > gap_reset_s) {
    ++counters.gaps;
    return SampleCheck::kGap;
  }
  return SampleCheck::kOk;
}

StepDetectorOptions StepDetectorOptions::paper() {
  StepDetectorOptions o;
  o.lowpass_hz = 0.0;
  o.min_step_interval_s = 0.0;
  o.refractory_fraction = 0.0;
  o.min_sigma_mps2 = 0.0;
  o.min_swing_mps2 = 0.0;
  o.bout_min_steps = 1;
  o.short_walk_min_steps = 0;
  o.short_walk_min_steps_gyro = 0;
  o.bout_min_steps_gyro = 0;
  o.stride_harmonic_ratio = 0.0;
  return o;
}

StepDetector::StepDetector(const StepDetectorOptions& options) : opt_(options), window_(options.window_s) {}

void StepDetector::reset() {
  have_last_ = false;
  filter_init_ = false;
  lp1_ = lp2_ = 0.0;
  window_.clear();
  last_defined_ = Symbol::kUndefined;
  period_max_ = period_min_ = 0.0;
  have_step_ = false;
  typical_interval_s_ = typical_before_s_ = 0.0;
  history_.clear();
  prev_stride_like_ = false;
}

double StepDetector::filter(double magnitude, double dt_s) {
  if (opt_.lowpass_hz <= 0.0) return magnitude;
  if (!filter_init_) {
    lp1_ = lp2_ = magnitude;
    filter_init_ = true;
    return magnitude;
  }
  // Two cascaded first-order sections, time-aware so irregular sampling is handled.
  return detail::lowpass2(lp1_, lp2_, magnitude, detail::lowpass_gain(dt_s, opt_.lowpass_hz));
}

bool StepDetector::gate_open() const {
  const double sigma = window_.sigma();
  return sigma > 0.0 && sigma >= opt_.min_sigma_mps2;
}

double StepDetector::swing_between(TimeNs from_ns, TimeNs to_ns) const {
  double hi = -1e300, lo = 1e300;
  for (const auto& h : history_) {
    if (h.t_ns < from_ns || h.t_ns > to_ns) continue;
    hi = std::max(hi, h.value);
    lo = std::min(lo, h.value);
  }
  return hi >= lo ? hi - lo : 0.0;
}

StepDetector::Symbol StepDetector::quantise(double value) const {
  if (window_.size() < 2) return Symbol::kUndefined;
  const double mean = window_.mean();
  const double sigma = window_.sigma();
  if (sigma < opt_.min_sigma_mps2 || sigma <= 0.0) return Symbol::kUndefined;
  if (value > mean + opt_.k_sigma * sigma) return Symbol::kHigh;
  if (value < mean - opt_.k_sigma * sigma) return Symbol::kLow;
  return Symbol::kUndefined;
}

std::optional<StepCandidate> StepDetector::on_symbol(Symbol sym, TimeNs t_ns, double value) {
  if (sym == Symbol::kUndefined) return std::nullopt;
  if (sym == Symbol::kHigh) {
    // Consecutive equal symbols merge; track the extreme of the current run.
    period_max_ = (last_defined_ == Symbol::kHigh) ? std::max(period_max_, value) : value;
    last_defined_ = Symbol::kHigh;
    return std::nullopt;
  }
  const bool completes_period = (last_defined_ == Symbol::kHigh);  // "10" or "1 undefined 0"
  const double prev_min = period_min_;
  period_min_ = (last_defined_ == Symbol::kLow) ? std::min(period_min_, value) : value;
  last_defined_ = Symbol::kLow;
  if (!completes_period) return std::nullopt;
  const double swing = period_max_ - std::min(prev_min, value);
  const double interval = have_step_ ? ns_to_s(t_ns - last_step_ns_) : 0.0;
  const double refractory = std::max(opt_.min_step_interval_s, opt_.refractory_fraction * typical_interval_s_);
  if (have_step_ && interval < refractory) return std::nullopt;
  if (swing < opt_.min_swing_mps2) return std::nullopt;
  typical_before_s_ = typical_interval_s_;
  if (have_step_ && interval <= opt_.max_step_interval_s) {
    // Running average of the step interval for the adaptive refractory.
    typical_interval_s_ = typical_interval_s_ > 0.0 ? typical_interval_s_ + kIntervalGain * (interval - typical_interval_s_) : interval;
  } else if (have_step_) {
    typical_interval_s_ = 0.0;  // a pause: forget the cadence
  }
  StepCandidate c;
  c.t_ns = t_ns;
  c.swing_mps2 = swing;
  c.interval_s = interval;
  have_step_ = true;
  last_step_ns_ = t_ns;
  return c;
}

bool StepDetector::stride_like(TimeNs t_ns, double interval_s, bool* by_gyro) const {
  if (by_gyro) *by_gyro = false;
  const double min_interval_s = running_ ? opt_.running_stride_min_interval_s : opt_.stride_min_interval_s;
  if (opt_.stride_harmonic_ratio <= 0.0 || interval_s < min_interval_s ||
      interval_s > opt_.stride_max_interval_s) {
    return false;
  }
  // Single-bin DFTs over the last two intervals (whole cycles, so the bins are orthogonal):
  // |a| at f1 = 1/I (stride) and f2 = 2/I (step); then the swing at f1 and at f1/2.
  const TimeNs from = t_ns - s_to_ns(2.0 * interval_s);
  double mean = 0.0;
  int n = 0;
  for (const auto& h : history_) {
    if (h.t_ns < from) continue;
    mean += h.value;
    ++n;
  }
  if (n < 8) return false;
  mean /= n;
  std::complex<double> x1 = 0.0, x2 = 0.0;
  for (const auto& h : history_) {
    if (h.t_ns < from) continue;
    const double ph = 2.0 * kPi * ns_to_s(h.t_ns - t_ns) / interval_s;
    x1 += (h.value - mean) * std::polar(1.0, -ph);
    x2 += (h.value - mean) * std::polar(1.0, -2.0 * ph);
  }
  const double a1 = std::abs(x1);
  const double step_power = a1 > 0.0 ? std::abs(x2) / a1 : 0.0;
  if (step_power <= opt_.stride_harmonic_ratio) return false;
  if (const std::optional<bool> rotates = rotates_at(t_ns, interval_s)) {
    if (by_gyro) *by_gyro = true;
    return *rotates;
  }
  // No gyroscope over the intervals: the tilt (rad, small-angle).
  const SwingAmplitudes tilt = swing_amplitudes(history_, from, t_ns, interval_s, [](const Tilted& h) { return h.dir; });
  return tilt.at_interval > opt_.stride_min_tilt_rad && tilt.at_interval > tilt.at_half;
}

std::optional<bool> StepDetector::rotates_at(TimeNs t_ns, double interval_s) const {
  const TimeNs from = t_ns - s_to_ns(2.0 * interval_s);
  const TimeNs slack = s_to_ns(0.25 * interval_s);
  TimeNs first = 0, last = 0, widest_gap = 0;
  int n = 0;
  for (const auto& r : rates_) {
    if (r.t_ns < from || r.t_ns > t_ns) continue;
    if (n == 0) first = r.t_ns;
    else widest_gap = std::max(widest_gap, r.t_ns - last);
    last = r.t_ns;
    ++n;
  }
  // The samples must cover the two intervals (no batch still to come, no hole in the stream).
  if (n < 8 || first - from > slack || t_ns - last > slack || widest_gap > slack) return std::nullopt;
  const SwingAmplitudes rot = swing_amplitudes(rates_, from, t_ns, interval_s, [](const Rate& r) { return r.rate_radps; });
  return rot.at_interval > opt_.stride_min_rotation_radps && rot.at_interval > rot.at_half;  // rad/s
}

void StepDetector::feed(const GyroSample& s) {
  if (opt_.stride_harmonic_ratio <= 0.0 || opt_.stride_min_rotation_radps <= 0.0 || !s.rate_radps.allFinite()) return;
  if (!rates_.empty() && s.t_ns <= rates_.back().t_ns) return;  // duplicates and backwards: the Pdr counts them
  rates_.push_back({s.t_ns, s.rate_radps});
  const TimeNs keep = s_to_ns(2.0 * opt_.stride_max_interval_s);
  while (!rates_.empty() && rates_.front().t_ns < s.t_ns - keep) rates_.pop_front();
}

namespace {
constexpr double kPeriodBinS = 0.02;  // the run's |a| in 20 ms bins for its autocorrelation
}  // namespace

double StepDetector::running_step_period_s(TimeNs t_ns) const {
  const std::size_t n = static_cast<std::size_t>(std::lround(opt_.running_period_window_s / kPeriodBinS));
  if (n < 4) return 0.0;
  const TimeNs from = t_ns - s_to_ns(static_cast<double>(n) * kPeriodBinS);
  std::vector<double> sum(n, 0.0);
  std::vector<int> count(n, 0);
  for (const auto& h : history_) {
    if (h.t_ns < from || h.t_ns >= t_ns) continue;
    const auto i = static_cast<std::size_t>(static_cast<double>(h.t_ns - from) * 1e-9 / kPeriodBinS);
    if (i < n) sum[i] += h.raw, ++count[i];
  }
  // a bin without a sample (a rate below 50 Hz, jitter) repeats the previous one; a hole of more
  // than 0.1 s (or none at the start) gives no period
  std::vector<double> x(n);
  std::size_t empty_run = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (count[i] > 0) {
      x[i] = sum[i] / count[i];
      empty_run = 0;
    } else {
      if (i == 0 || static_cast<double>(++empty_run) * kPeriodBinS > 0.1) return 0.0;
      x[i] = x[i - 1];
    }
  }
  const auto lag_min = static_cast<std::size_t>(std::lround(opt_.running_stride_lag_min_s / kPeriodBinS));
  const auto lag_max = std::min(n / 2, static_cast<std::size_t>(std::lround(opt_.running_stride_lag_max_s / kPeriodBinS)));
  const detail::BestLag stride = detail::best_autocorrelation(x, lag_min, lag_max);
  if (stride.lag == 0 || stride.corr < opt_.running_period_min_corr) return 0.0;
  return 0.5 * static_cast<double>(stride.lag) * kPeriodBinS;
}

bool StepDetector::fill_run(const StepCandidate& c, std::vector<StepCandidate>& out) {
  // the shortest period the autocorrelation can give (its shortest stride lag, in bins): an
  // interval shorter than 2 of them less the tolerance holds one step, and needs no period
  const double shortest_period_s =
      0.5 * kPeriodBinS * std::max(1.0, std::round(opt_.running_stride_lag_min_s / kPeriodBinS));
  if (!running_ || opt_.running_period_window_s <= 0.0 || !(c.interval_s > 0.0) ||
      c.interval_s > opt_.running_fill_max_interval_s ||
      c.interval_s < (2.0 - opt_.running_fill_tolerance) * shortest_period_s)
    return false;
  const double period = running_step_period_s(c.t_ns);
  if (!(period > 0.0)) return false;
  const double ratio = c.interval_s / period;
  const long steps = std::lround(ratio);
  if (steps < 2 || std::abs(ratio - static_cast<double>(steps)) > opt_.running_fill_tolerance) return false;
  const double each = c.interval_s / static_cast<double>(steps);
  for (long k = steps - 1; k >= 0; --k) {
    StepCandidate s = c;
    s.t_ns = c.t_ns - s_to_ns(static_cast<double>(k) * each);
    s.interval_s = each;
    if (k > 0) s.placed_from_ns = c.t_ns - s_to_ns(c.interval_s);
    out.push_back(s);
  }
  stride_steps_added_ += steps - 1;
  if (typical_before_s_ > 0.0)  // the cadence goes on at the period (the interval held several steps)
    typical_interval_s_ = typical_before_s_ + kIntervalGain * (each - typical_before_s_);
  prev_stride_like_ = false;
  return true;
}

void StepDetector::split_strides(const StepCandidate& c, std::vector<StepCandidate>& out) {
  if (fill_run(c, out)) return;
  bool by_gyro = false;
  const bool like = stride_like(c.t_ns, c.interval_s, &by_gyro);
  // Walking: two in a row (one odd long interval may be a pause), or one of twice the bout's
  // cadence whose swing the gyroscope saw. Running: one is enough.
  const double tol = opt_.walking_single_stride_tol;
  const bool two_steps_of_the_bout = tol > 0.0 && by_gyro && typical_before_s_ > 0.0 &&
                                     std::abs(c.interval_s / (2.0 * typical_before_s_) - 1.0) <= tol;
  const bool split = like && (prev_stride_like_ || (running_ && opt_.running_single_stride) || two_steps_of_the_bout);
  prev_stride_like_ = like;
  if (!split) {
    out.push_back(c);
    return;
  }
  if (typical_before_s_ > 0.0)  // the cadence goes on at the half interval (it is two steps)
    typical_interval_s_ = typical_before_s_ + kIntervalGain * (0.5 * c.interval_s - typical_before_s_);
  StepCandidate mid = c;
  mid.t_ns = c.t_ns - s_to_ns(0.5 * c.interval_s);
  mid.interval_s = 0.5 * c.interval_s;
  mid.placed_from_ns = c.t_ns - s_to_ns(c.interval_s);
  StepCandidate second = c;
  second.interval_s = 0.5 * c.interval_s;
  out.push_back(mid);
  out.push_back(second);
  ++stride_steps_added_;
}

std::optional<double> StepDetector::accept(TimeNs t_ns, bool finite, double raw, double* dt_s) {
  const SampleCheck check = check_sample(t_ns, finite, last_t_ns_, have_last_, opt_.gap_reset_s, counters_);
  if (check == SampleCheck::kNonFinite || check == SampleCheck::kDuplicate || check == SampleCheck::kBackwards)
    return std::nullopt;
  if (check == SampleCheck::kGap) reset();
  *dt_s = have_last_ ? ns_to_s(t_ns - last_t_ns_) : 0.0;
  have_last_ = true;
  last_t_ns_ = t_ns;
  const double value = filter(raw, *dt_s);
  window_.push(t_ns, value);
  return value;
}

std::vector<StepCandidate> StepDetector::feed(const AccelSample& s) {
  std::vector<StepCandidate> out;
  double dt_s = 0.0;
  const std::optional<double> accepted = accept(s.t_ns, s.acc_mps2.allFinite(), s.acc_mps2.norm(), &dt_s);
  if (!accepted) return out;
  const double value = *accepted;
  if (opt_.stride_harmonic_ratio > 0.0) {
    // Tilt: the specific force low-passed (same two sections as |a|) and normalised.
    if (history_.empty()) {
      lpv1_ = lpv2_ = s.acc_mps2;
    } else {
      detail::lowpass2(lpv1_, lpv2_, s.acc_mps2, detail::lowpass_gain(dt_s, std::max(opt_.lowpass_hz, 1.0)));
    }
    const double norm = lpv2_.norm();
    history_.push_back({s.t_ns, value, s.acc_mps2.norm(), norm > 1e-6 ? Eigen::Vector3d(lpv2_ / norm) : Eigen::Vector3d::UnitZ()});
    const TimeNs keep = s_to_ns(2.0 * opt_.stride_max_interval_s);
    while (!history_.empty() && history_.front().t_ns < s.t_ns - keep) history_.pop_front();
  }
  const auto c = on_symbol(quantise(value), s.t_ns, value);
  if (c) split_strides(*c, out);
  return out;
}

std::vector<StepCandidate> StepDetector::feed_value(TimeNs t_ns, double value_in) {
  std::vector<StepCandidate> out;
  double dt_s = 0.0;
  const std::optional<double> value = accept(t_ns, std::isfinite(value_in), value_in, &dt_s);
  if (!value) return out;
  if (const auto c = on_symbol(quantise(*value), t_ns, *value)) out.push_back(*c);
  return out;
}

std::vector<StepCandidate> detect_steps(const std::vector<AccelSample>& samples,
                                        const StepDetectorOptions& options, SampleCounters* counters) {
  StepDetector detector(options);
  BoutGate<StepCandidate> gate(options.bout_min_steps, options.max_step_interval_s, options.short_walk_min_steps);
  std::vector<StepCandidate> steps;
  std::int64_t gaps_seen = 0;
  for (const auto& s : samples) {
    const auto candidates = detector.feed(s);
    if (detector.counters().gaps != gaps_seen) {  // a gap resets the bout as well
      gaps_seen = detector.counters().gaps;
      for (auto& released : gate.end_bout()) steps.push_back(released);
    }
    for (const auto& c : candidates) {
      for (auto& released : gate.push(c.t_ns, c)) steps.push_back(released);
    }
  }
  for (auto& released : gate.finish()) steps.push_back(released);
  if (counters) *counters = detector.counters();
  return steps;
}

}  // namespace pdnav::pdr
