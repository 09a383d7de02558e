// A running sum over the samples of the last span_s seconds: the sliding windows of the PDR
// stages (the motion classifier's |a|, angular-rate and kinematic windows, the step detector's
// |a| statistics, the heading's gravity mean) are all this one shape.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <deque>
#include <utility>

#include <Eigen/Core>

#include "pdnav/geo/units.h"

namespace pdnav::pdr {

/// T: a value with += and -= (double, an Eigen vector or matrix); zero is its additive identity.
/// A sample is dropped once it is span_s or more older than the newest. The sum is re-derived
/// from the kept samples every kResumEvery pushes so add/subtract rounding stays bounded on
/// sessions of any length.
template <typename T>
class TimeWindowSum {
 public:
  static constexpr std::int64_t kResumEvery = 4096;

  TimeWindowSum(double span_s, const T& zero) : span_ns_(s_to_ns(span_s)), zero_(zero), sum_(zero) {}

  void push(TimeNs t_ns, const T& value) {
    samples_.emplace_back(t_ns, value);
    sum_ += value;
    const TimeNs horizon = t_ns - span_ns_;
    while (!samples_.empty() && samples_.front().first <= horizon) {
      sum_ -= samples_.front().second;
      samples_.pop_front();
    }
    if (++pushes_since_resum_ >= kResumEvery) {
      pushes_since_resum_ = 0;
      sum_ = zero_;
      for (const auto& s : samples_) sum_ += s.second;
    }
  }
  void clear() {
    samples_.clear();
    sum_ = zero_;
    pushes_since_resum_ = 0;
  }
  bool empty() const { return samples_.empty(); }
  std::size_t size() const { return samples_.size(); }
  const T& sum() const { return sum_; }
  /// Time from the oldest kept sample to the newest (0 when fewer than two).
  double covered_s() const { return samples_.size() < 2 ? 0.0 : ns_to_s(samples_.back().first - samples_.front().first); }

 private:
  TimeNs span_ns_;
  T zero_;
  T sum_;
  std::deque<std::pair<TimeNs, T>> samples_;
  std::int64_t pushes_since_resum_ = 0;
};

/// The window of a scalar x kept as (x, x^2), for its standard deviation.
class TimeWindowMoments {
 public:
  explicit TimeWindowMoments(double span_s) : w_(span_s, Eigen::Vector2d::Zero()) {}
  void push(TimeNs t_ns, double x) { w_.push(t_ns, Eigen::Vector2d(x, x * x)); }
  void clear() { w_.clear(); }
  std::size_t size() const { return w_.size(); }
  double mean() const { return w_.empty() ? 0.0 : w_.sum()[0] / static_cast<double>(w_.size()); }
  /// Population standard deviation (0 with fewer than two samples).
  double sigma() const {
    if (w_.size() < 2) return 0.0;
    const double n = static_cast<double>(w_.size());
    const double mu = w_.sum()[0] / n;
    return std::sqrt(std::max(0.0, w_.sum()[1] / n - mu * mu));
  }

 private:
  TimeWindowSum<Eigen::Vector2d> w_;
};

}  // namespace pdnav::pdr
