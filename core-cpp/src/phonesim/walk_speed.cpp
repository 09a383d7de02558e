// A recording as the same walk taken faster (phonesim/walk_speed.h).
#include "pdnav/phonesim/walk_speed.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <variant>

#include <Eigen/Core>

namespace pdnav::phonesim {

namespace {

/// Zero-phase low-pass of a vector series at cutoff_hz: two first-order sections forward, then
/// the same backward (exact gains for the series' own time steps).
std::vector<Eigen::Vector3d> zero_phase_lowpass(const std::vector<TimeNs>& t, const std::vector<Eigen::Vector3d>& x,
                                                double cutoff_hz) {
  std::vector<Eigen::Vector3d> y = x;
  if (x.empty()) return y;
  const auto gain = [&](std::size_t a, std::size_t b) {
    const double dt = std::abs(static_cast<double>(t[b] - t[a])) * 1e-9;
    return 1.0 - std::exp(-2.0 * kPi * cutoff_hz * dt);
  };
  Eigen::Vector3d s1 = y.front(), s2 = y.front();
  for (std::size_t i = 0; i < y.size(); ++i) {
    const double g = i ? gain(i - 1, i) : 0.0;
    s1 += g * (y[i] - s1);
    s2 += g * (s1 - s2);
    y[i] = s2;
  }
  s1 = s2 = y.back();
  for (std::size_t i = y.size(); i-- > 0;) {
    const double g = i + 1 < y.size() ? gain(i, i + 1) : 0.0;
    s1 += g * (y[i] - s1);
    s2 += g * (s1 - s2);
    y[i] = s2;
  }
  return y;
}

}  // namespace

std::vector<Sample> at_walk_speed(const std::vector<Sample>& in, double k, double slow_hz) {
  if (!(k >= 0.25 && k <= 4.0)) throw std::invalid_argument("at_walk_speed: the speed factor must be in [0.25, 4]");
  if (!(slow_hz > 0.0) || !std::isfinite(slow_hz)) throw std::invalid_argument("at_walk_speed: slow_hz must be > 0");
  TimeNs t0 = std::numeric_limits<TimeNs>::max();
  for (const Sample& s : in) t0 = std::min(t0, sample_time_ns(s));
  const auto faster = [&](TimeNs t) { return t0 + static_cast<TimeNs>(std::llround(static_cast<double>(t - t0) / k)); };

  // The slow part of each accelerometer stream (calibrated, uncalibrated), on its own time line.
  std::vector<TimeNs> ta, tu;
  std::vector<Eigen::Vector3d> xa, xu;
  for (const Sample& s : in) {
    if (const auto* a = std::get_if<AccelSample>(&s); a && a->acc_mps2.allFinite()) ta.push_back(a->t_ns), xa.push_back(a->acc_mps2);
    if (const auto* u = std::get_if<UncalAccelSample>(&s); u && u->acc_mps2.allFinite()) tu.push_back(u->t_ns), xu.push_back(u->acc_mps2);
  }
  const std::vector<Eigen::Vector3d> slow_a = zero_phase_lowpass(ta, xa, slow_hz), slow_u = zero_phase_lowpass(tu, xu, slow_hz);
  std::size_t ia = 0, iu = 0;
  const double k2 = k * k;
  // the gait (what is above the slow part) k^2 larger; slow[i] is this reading's slow part
  const auto gait_faster = [k2](Eigen::Vector3d& acc, const std::vector<Eigen::Vector3d>& slow, std::size_t& i) {
    if (!acc.allFinite()) return;
    const Eigen::Vector3d& g = slow[i++];
    acc = g + k2 * (acc - g);
  };

  std::vector<Sample> out;
  out.reserve(in.size());
  for (Sample s : in) {
    if (std::holds_alternative<GnssRawSample>(s) || std::holds_alternative<NavMessageSample>(s) ||
        std::holds_alternative<GnssStatusSample>(s) || std::holds_alternative<AgcSample>(s))
      continue;
    std::visit(
        [&](auto& x) {
          using T = std::decay_t<decltype(x)>;
          const TimeNs before = x.t_ns;
          x.t_ns = faster(x.t_ns);
          if constexpr (has_utc<T>::value) {
            if (x.utc_ms != kMissingInt) x.utc_ms -= (before - x.t_ns) / 1000000;
          }
          if constexpr (std::is_same_v<T, AccelSample>) {
            gait_faster(x.acc_mps2, slow_a, ia);
          } else if constexpr (std::is_same_v<T, UncalAccelSample>) {
            gait_faster(x.acc_mps2, slow_u, iu);
          } else if constexpr (std::is_same_v<T, GyroSample>) {
            x.rate_radps *= k;
          } else if constexpr (std::is_same_v<T, UncalGyroSample>) {
            const Eigen::Vector3d drift = x.drift_radps.allFinite() ? x.drift_radps : Eigen::Vector3d::Zero();
            x.rate_radps = drift + k * (x.rate_radps - drift);
          } else if constexpr (std::is_same_v<T, FixSample>) {
            x.speed_mps *= k;
            x.speed_accuracy_mps *= k;
          } else if constexpr (std::is_same_v<T, MetaSample>) {
            if (x.key == "TruthStepsFromNanos" || x.key == "TruthStepsToNanos") {
              try {
                x.value = std::to_string(faster(std::stoll(x.value)));
              } catch (const std::exception&) {
              }
            } else if (x.key == "TruthCadenceHz") {
              try {
                char buf[32];
                std::snprintf(buf, sizeof buf, "%.3f", std::stod(x.value) * k);
                x.value = buf;
              } catch (const std::exception&) {
              }
            }
          }
        },
        s);
    out.push_back(std::move(s));
  }
  return out;
}

}  // namespace pdnav::phonesim
